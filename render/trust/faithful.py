"""The faithfulness certificate in words, written once for every place that says it: the last line of a
render and of a simulation, a notebook's table, a gallery card, a comparison's labels and summary line.

It reads the certificate as metadata.json holds it (certify.Certificate.to_dict()) and imports nothing, so
`render.RenderResult` says it without starting Taichi. The gallery reads metadata from other versions and
other hands: a value that is not a number reads "?" rather than failing.
"""
from __future__ import annotations


def _number(x) -> bool:
    return isinstance(x, (int, float)) and not isinstance(x, bool)


def _g(x) -> str:
    return f"{x:g}" if _number(x) else "?"


def until(t, duration) -> str:
    """A faithful time: "the end" once it lasts the video, else its seconds ("8.68 s")."""
    if not _number(t):
        return "?"
    return "the end" if _number(duration) and t >= duration else f"{t:.2f} s"


def sentence(f: dict, duration, brief: bool = False) -> str:
    """The certificate `f` of a video `duration` s long: "faithful until 8.68 s (median 12.24 s, 1 % through
    20 s) at 0.001 rad": until when the first and the median certified pendulum stay faithful, the share that
    does to the end, and the tolerance. Brief, for a row headed "faithful": "until 8.68 s (median 12.24 s)
    at 0.001 rad"."""
    first, median = until(f.get("faithful_until_s"), duration), until(f.get("median_until_s"), duration)
    unit = f.get("unit")
    at = f"at {_g(f.get('tolerance'))} {unit if isinstance(unit, str) else ''}".rstrip()
    if brief:
        return f"until {first} (median {median}) {at}"
    share = f.get("fraction_faithful")
    share = f"{100 * share:.0f}" if _number(share) else "?"
    return f"faithful until {first} (median {median}, {share} % through {_g(duration)} s) {at}"
