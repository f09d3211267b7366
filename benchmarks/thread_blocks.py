"""How Taichi's CPU backend shares a parallel loop between its threads: the finding behind runtime.SPREAD.

    python benchmarks/thread_blocks.py [--threads 2]

A kernel of heavy, equal iterations is timed at several loop lengths on 1 thread and on --threads, plainly,
with ti.loop_config(block_dim=1), and spread as render/physics/runtime.py's SPREAD spreads the advance
kernel (SPREAD iterations per item, the first does the work). Where the plain loop takes as long on several
threads as on one, its items went to one thread: Taichi 1.7.4 hands out blocks of at least 512 iterations,
whatever block_dim says. The offline cache is off, so every variant is compiled as written.
"""
import argparse
import subprocess
import sys
import time

WORK = 1_900_000  # sin evaluations per launch, shared among the items


def child(threads: int):
    import taichi as ti
    ti.init(arch=ti.cpu, cpu_max_num_threads=threads, offline_cache=False, log_level=ti.ERROR)
    from render.physics.runtime import SPREAD
    x = ti.field(ti.f64, 100_000)

    @ti.func
    def work(g, reps):
        a = ti.cast(g, ti.f64)
        for _ in range(reps):
            a = ti.sin(a) + 1.0
        x[g] = a

    @ti.kernel
    def plain(n: ti.i32, reps: ti.i32):
        for g in range(n):
            work(g, reps)

    @ti.kernel
    def block_dim_1(n: ti.i32, reps: ti.i32):
        ti.loop_config(block_dim=1)
        for g in range(n):
            work(g, reps)

    @ti.kernel
    def spread(n: ti.i32, reps: ti.i32):
        for t in range(n * SPREAD):
            if t % SPREAD == 0:
                work(t // SPREAD, reps)

    for n in (95, 600, 6000):
        row = []
        for kernel in (plain, block_dim_1, spread):
            kernel(n, WORK // n)  # compiles
            t = time.perf_counter()
            for _ in range(5):
                kernel(n, WORK // n)
            ti.sync()
            row.append(f"{kernel.__name__} {1e3 * (time.perf_counter() - t) / 5:6.1f} ms")
        print(f"{threads} thread(s), {n:5d} items: " + ", ".join(row), flush=True)


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--threads", type=int, default=2, help="threads to compare with one (default: 2)")
    ap.add_argument("--child", type=int, help=argparse.SUPPRESS)
    args = ap.parse_args()
    if args.child:
        return child(args.child)
    for threads in (1, args.threads):  # each in its own process: Taichi's thread count is set once per init
        subprocess.run([sys.executable, __file__, "--child", str(threads)], check=True)


if __name__ == "__main__":
    main()
