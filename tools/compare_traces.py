"""Compare two tick traces of examples/embedded (--trace): same shape, and every value equal to
RTOL relative to the scale of its group of columns (the largest magnitude in the group over the
whole run). GROUPS (e.g. "6,6": the six torques, then the shaking force and moment) splits the
columns into groups whose values share a scale: a force-balanced design's shaking force is zero up
to rounding, so it is compared at the scale of the whole shaking wrench rather than of its own
rounding noise. Standard library only (make test-embedded)."""
import sys


def read(path):
    with open(path) as f:
        return [[float(x) for x in line.split()] for line in f if line.strip()]


def main(argv):
    if len(argv) not in (4, 5):
        print("usage: compare_traces.py A B RTOL [GROUPS]", file=sys.stderr)
        return 2
    a, b, rtol = read(argv[1]), read(argv[2]), float(argv[3])
    if len(a) != len(b) or any(len(x) != len(y) for x, y in zip(a, b)) or not a:
        print(f"traces differ in shape: {len(a)} and {len(b)} rows", file=sys.stderr)
        return 1
    cols = len(a[0])
    sizes = [int(x) for x in argv[4].split(",")] if len(argv) == 5 else [1] * cols
    if sum(sizes) != cols:
        print(f"GROUPS {sizes} does not add up to the {cols} columns", file=sys.stderr)
        return 2
    worst, start = [], 0
    for size in sizes:
        group = range(start, start + size)
        scale = max(max(abs(r[c]) for r in a for c in group), 1e-300)
        err = max(abs(x[c] - y[c]) for x, y in zip(a, b) for c in group) / scale
        worst.append(err)
        start += size
    text = ", ".join(f"{e:.2g}" for e in worst)
    print(f"{len(a)} ticks x {cols} values: largest difference per group (of the group's scale): {text} "
          f"(tolerance {rtol:g})")
    return 0 if max(worst) <= rtol else 1


if __name__ == "__main__":
    sys.exit(main(sys.argv))
