"""Generated files compared with their generator: the same text, numbers equal to round-off.

A generator's floats go through NumPy/BLAS, whose last bits depend on the processor's kernels
(OpenBLAS picks one per CPU), so a byte-for-byte comparison fails on another machine for a
difference of 1 ulp. Everything but the numbers must be identical; the numbers agree to `rtol`."""
from __future__ import annotations

import re

_NUMBER = re.compile(r"[-+]?(?:\d+\.\d*|\.\d+|\d+)(?:[eE][-+]?\d+)?")


def text_differences(shipped: str, generated: str, rtol: float = 1e-13) -> list[str]:
    """What differs: lines whose words differ, or numbers beyond `rtol` (relative, floor 1e-300)."""
    out: list[str] = []
    a_lines, b_lines = shipped.splitlines(), generated.splitlines()
    if len(a_lines) != len(b_lines):
        return [f"{len(a_lines)} lines against {len(b_lines)}"]
    for k, (a, b) in enumerate(zip(a_lines, b_lines), start=1):
        if _NUMBER.sub("#", a) != _NUMBER.sub("#", b):
            out.append(f"line {k}: {a!r} != {b!r}")
            continue
        for x, y in zip(_NUMBER.findall(a), _NUMBER.findall(b)):
            fx, fy = float(x), float(y)
            if abs(fx - fy) > rtol * max(abs(fx), abs(fy), 1e-300):
                out.append(f"line {k}: {x} != {y}")
    return out
