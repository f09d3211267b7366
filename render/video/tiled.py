"""One map across a Dask cluster (`render MAP --scheduler ADDR` or `--tiles N`): its bands integrated by Dask
workers (render/maps/tiles.py), its frames put together here and encoded as a local render's are: the same
bytes, frame for frame.

The certificate runs once, here, before any task, and every band gets it. A band's task is keyed by the
scene's hash (pendulum-tile-<hash>-<band>-of-<bands>-<nonce>) and its result names the scene it drew, which is
checked: a band of another scene is an error, never part of a frame. A band whose worker dies is run again by
the scheduler on another worker (up to its distributed.scheduler.allowed-failures), one that raised (say, out
of memory) up to RETRIES more times; the watchdog's verdict is a result, not raised, since it would come again.
A band that cannot be had fails the render at once, its other bands cancelled, before anything is written
(exit 1).

Dask's client and the cluster's addresses are made here, for `batch --scheduler` (whole presets as tasks,
render/commands/batch.py) too; so this module imports neither Taichi nor Dask until a render starts.
"""
from __future__ import annotations

import os
import re
import time
from contextlib import contextmanager, suppress

from ..errors import BatchError, SceneError, SimulationError
from ..physics import held_stderr
from .atomic import signals_held

RETRIES = 2  # reruns of a band that raised (a worker's death is the scheduler's to retry)
ENV = "DASK_SCHEDULER_ADDRESS"  # the cluster `batch` and a map's `render` use without --scheduler
CONNECT_TIMEOUT = "10s"  # how long Client keeps trying a scheduler (it retries a refused connection till then)
WORKERS_TIMEOUT_S = 30.0  # how long a reached scheduler may be without a worker (one may be starting)


def scheduler_address(text: str | None, what: str = "--scheduler") -> str | None:
    """'host:port' or 'tcp://host:port' (any Dask scheme); checked here, since a bad one hangs Client. None for
    none given; an empty one is refused (it would quietly render locally). `what` names where it came from."""
    if text is None:
        return None
    address = text if "://" in text else f"tcp://{text}"
    # host:port or [IPv6]:port; the port a number Dask can connect to (a bad one made Client raise in a
    # background thread and hang; none, "missing port number" after Client's 20 s timeout, with a traceback)
    m = re.fullmatch(r"(tcp|tls|ws|wss|ucx|inproc)://(\[[0-9A-Fa-f:.]+\]|[^\s/:\[\]]+):([^\s/]*)", address)
    port = m and m.group(3)
    if not m or not (port.isascii() and port.isdigit() and 0 < int(port) < 65536):
        raise SceneError(f"{what} {text!r}: expected an address like tcp://host:8786 (a port from 1 to 65535)")
    return address


def env_address() -> str | None:
    """The scheduler $DASK_SCHEDULER_ADDRESS (Dask's own variable) names, checked; None where it is unset or
    empty, as an empty variable is taken by convention."""
    return scheduler_address(os.environ.get(ENV) or None, f"${ENV}")


def connect(address: str):
    """A Client of the Dask scheduler at `address`, which has a worker; BatchError (exit 1) when it cannot be
    reached or has had no worker for WORKERS_TIMEOUT_S (its tiles would wait for one forever, saying nothing;
    an adaptive cluster must so have one up within that time)."""
    from dask.distributed import Client
    try:
        client = Client(address, timeout=CONNECT_TIMEOUT, set_as_default=False)
    except Exception as e:  # noqa: BLE001 - whatever Dask raises here (OSError, TimeoutError, ...)
        raise BatchError(f"cannot reach the Dask scheduler at {address}: {e}") from None
    try:
        client.wait_for_workers(1, timeout=WORKERS_TIMEOUT_S)
    except Exception:  # noqa: BLE001 - TimeoutError, or the scheduler gone meanwhile
        close(client)
        raise BatchError(f"the Dask scheduler at {address} has no worker (waited {WORKERS_TIMEOUT_S:g} s); start "
                         f"one with `dask worker {address}`") from None
    return client


def close(client):
    """Close a Client whose scheduler may be gone: the error being reported, not close()'s, is the one line."""
    with suppress(Exception):
        client.close()


@contextmanager
def quiet():
    """distributed's logging and warnings held back while a cluster works for this process: a lost scheduler
    is reported as one line by collect(), not after 25 lines of its client's traceback, and a LocalCluster's
    scheduler starts an HTTP server on 8787 even without a dashboard, and warns where that port is taken.
    distributed gives its loggers (distributed.client, .gc, ...) levels of their own and stops their
    propagation, so each is quieted, as are tornado's."""
    import logging
    import warnings
    import distributed  # noqa: F401 - its import configures the loggers quieted here
    names = ["distributed", "tornado", *(n for n in logging.root.manager.loggerDict
                                         if n.partition(".")[0] in ("distributed", "tornado"))]
    levels = {n: logging.getLogger(n).level for n in names}
    for n in names:
        logging.getLogger(n).setLevel(logging.CRITICAL)
    try:
        with warnings.catch_warnings():
            warnings.filterwarnings("ignore", message=r"Port \d+ is already in use", category=UserWarning)
            yield
    finally:
        for n, level in levels.items():
            logging.getLogger(n).setLevel(level)


def check(scene, how: str):
    """Bad input before any work: a tiled render of a scene that is not a map, or of a map whose extras
    (energy, audio) read the whole system in one process."""
    if not scene.fractal:
        raise SceneError(f"{scene.source}: {how} splits a map (effects = [\"fractal\"]) into tiles; this preset is "
                         f"not one (render it without {how.split()[0]})")
    extra = [e for e in ("energy", "audio") if scene.has(e)]
    if extra:
        raise SceneError(f"{scene.source}: effects: {extra[0]!r} is measured over the whole system in one process; "
                         f"a tiled map ({how}) cannot take it")


@contextmanager
def cluster(address: str | None, workers: int | None):
    """A Client: of the scheduler at `address`, or of a LocalCluster of `workers` single-threaded worker
    processes on loopback, closed after the block."""
    if address:
        with quiet():
            client = connect(address)
            try:
                yield client
            finally:
                close(client)
        return
    import logging
    import tempfile
    import dask
    from dask.distributed import Client, LocalCluster
    # its scratch space (lock files) in a folder removed after, not left in $TMPDIR/dask-scratch-space
    with tempfile.TemporaryDirectory(prefix="pendulum-dask-", ignore_cleanup_errors=True) as scratch, quiet(), \
            dask.config.set({"temporary-directory": scratch}):
        local = None
        try:
            # The worker processes start with fd 2 held (render/physics/held_stderr.py), and what they write there
            # is dropped: a Ctrl-C to the terminal's process group reaches them too, and each printed its
            # KeyboardInterrupt's traceback beside our one line. One that reaches us meanwhile waits for the
            # cluster to be whole (signals_held): one closed half-started printed more at exit.
            with signals_held(), held_stderr.held(lambda text, ok: b""):
                local = LocalCluster(n_workers=workers, threads_per_worker=1, processes=True, host="127.0.0.1",
                                     dashboard_address=None, silence_logs=logging.ERROR)
        except BaseException:
            if local is not None:
                local.close()
            raise
        with local, Client(local, set_as_default=False) as client:
            yield client


class TiledSource:
    """The frames of a map whose bands Dask workers made: what pipeline.render encodes, as it does a Source's.

    prepared: what pipeline.prepare() gave (the scene as run, `chosen`, the certificate, its timings); bands: how
    many (default: one per worker thread of the cluster); threads: Taichi threads per band."""

    def __init__(self, prepared: tuple, client, bands: int | None = None, arch: str = "cpu",
                 threads: int | None = None):
        from ..maps import tiles
        from ..physics import grid, registry, runtime

        self.scene, self.chosen, self.cert, before = prepared
        scene = self.scene
        self.sim = registry.get(scene.system)(scene)  # its plan: the step, for metadata; no Taichi field
        self.name, self.frames, self.index = scene.name, scene.frames, -1
        lay = grid.plot(scene)
        rows = tiles.bands(lay.h, bands or sum(client.nthreads().values()) or 1)
        nonce, digest = os.urandom(4).hex(), scene.hash()
        t = time.perf_counter()
        futures = [client.submit(tiles.render_band, scene, r, self.cert, arch, threads, pure=False, retries=RETRIES,
                                 key=f"pendulum-tile-{digest[:16]}-{i}-of-{len(rows)}-{nonce}")
                   for i, r in enumerate(rows)]
        results = self.collect(futures, client)
        if any(r["scene_hash"] != digest for r in results):
            raise BatchError(f"{scene.name}: a tile of another scene came back from the cluster; nothing was written")
        self.arch = results[0]["arch"]
        self.timings = {**before, "simulate": time.perf_counter() - t, "draw": 0.0}  # on the cluster: both
        self.tiles = {"bands": len(rows), "workers": len(client.nthreads()),
                      "band_rows": [list(r["rows"]) for r in results],
                      "band_timings_s": [{k: round(v, 4) for k, v in r["timings"].items()} for r in results]}
        runtime.launched[:] = results[0]["kernels"]  # what metadata lists: a band's kernels, all bands' fields
        runtime.allocated.clear()
        for r in results:
            for name, size in r["fields"].items():
                runtime.allocated[name] = runtime.allocated.get(name, 0) + size
        self.assembly = tiles.Assembly(scene, results)
        self.canvas = self  # what pipeline.render asks a map's canvas for: summary(), result()

    def collect(self, futures: list, client) -> list[dict]:
        """The bands' results, top first, as they finish; the first failure cancels the others and raises. A
        cluster that has had no worker for WORKERS_TIMEOUT_S while bands wait (its workers died or were retired
        for good) fails the render too: the scheduler would hold them for a worker forever, saying nothing."""
        import threading

        from dask.distributed import as_completed

        index = {f.key: i for i, f in enumerate(futures)}
        results = [None] * len(futures)
        done, lost = threading.Event(), threading.Event()
        watch = threading.Thread(target=_watch_workers, args=(client, futures, done, lost), daemon=True)
        watch.start()
        try:
            for fut in as_completed(futures, loop=client.loop):
                try:
                    r = fut.result()
                except Exception as e:  # noqa: BLE001 - e.g. KilledWorker: a band's workers kept dying
                    if lost.is_set():
                        raise BatchError(f"{self.scene.name}: the Dask cluster has had no worker for "
                                         f"{WORKERS_TIMEOUT_S:g} s, with bands of the map still to run") from None
                    raise BatchError(f"{self.scene.name}: a tile could not be rendered on the cluster: "
                                     f"{type(e).__name__}: {e}") from None
                if "error" in r:
                    raise SimulationError(r["error"])
                results[index[fut.key]] = r
        finally:
            done.set()
            watch.join()
            client.cancel(futures)  # a no-op for finished bands; stops the others when one failed
        return results

    def summary(self) -> dict:
        """The map's summary() of the whole plot, and how its tiles were made."""
        return {**self.assembly.summary(), "tiles": self.tiles}

    def result(self) -> dict:
        """The map's result() of the whole plot, for its data (render/maps/data.py)."""
        return self.assembly.result()

    def next_frame(self, out=None):
        """The next frame as H×W×3 uint8, put together from the bands."""
        self.index += 1
        t = time.perf_counter()
        frame = self.assembly.frame(self.index, out)
        self.timings["draw"] += time.perf_counter() - t
        return frame


def _watch_workers(client, futures: list, done, lost, every_s: float = 1.0):
    """Until `done`: where the cluster has had no worker for WORKERS_TIMEOUT_S, set `lost` and cancel `futures`
    (their results then raise, and TiledSource.collect says why)."""
    alone = None
    while not done.wait(every_s):
        try:
            workers = client.nthreads()
        except Exception:  # noqa: BLE001 - the scheduler gone: the futures fail by themselves
            return
        if workers:
            alone = None
        elif alone is None:
            alone = time.monotonic()
        elif time.monotonic() - alone >= WORKERS_TIMEOUT_S:
            lost.set()
            client.cancel(futures)
            return
