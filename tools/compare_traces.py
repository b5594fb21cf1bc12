"""Compare two tick traces of examples/embedded (--trace): same shape, every value equal to
`rtol` relative to the largest magnitude of its column. Standard library only (make test-embedded)."""
import sys


def read(path):
    with open(path) as f:
        return [[float(x) for x in line.split()] for line in f if line.strip()]


def main(argv):
    if len(argv) != 4:
        print("usage: compare_traces.py A B RTOL", file=sys.stderr)
        return 2
    a, b, rtol = read(argv[1]), read(argv[2]), float(argv[3])
    if len(a) != len(b) or any(len(x) != len(y) for x, y in zip(a, b)) or not a:
        print(f"traces differ in shape: {len(a)} and {len(b)} rows", file=sys.stderr)
        return 1
    cols = len(a[0])
    worst = 0.0
    for c in range(cols):
        scale = max(max(abs(r[c]) for r in a), 1e-300)
        err = max(abs(x[c] - y[c]) for x, y in zip(a, b)) / scale
        worst = max(worst, err)
    print(f"{len(a)} ticks x {cols} values: largest difference {worst:.3g} of each column's scale (tolerance {rtol:g})")
    return 0 if worst <= rtol else 1


if __name__ == "__main__":
    sys.exit(main(sys.argv))
