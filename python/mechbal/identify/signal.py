"""From a raw log to uniform, filtered segments with accelerations.

The defaults (each a keyword of `prepare`):

1. **Time**: it must increase strictly (a step back or a repeated instant is refused, naming the
   row). Rows with a non-finite value (NaN, inf) are dropped and counted.
2. **Gaps**: a step longer than ``gap_factor`` (3) nominal steps (the median step) splits the log
   into segments, each processed on its own; shorter irregular steps are **resampled** onto a
   uniform grid of the nominal step (linear interpolation), the largest deviation reported.
3. **Filtering**: a zero-phase Butterworth low-pass of order 4 (``scipy.signal.sosfiltfilt``) on
   q, v and tau alike (the same filter on both sides of tau = Y pi). The cut-off ``cutoff_hz``
   defaults to 8 times the frequency below which 99 % of the velocity's power lies (from the
   data's spectrum), at most 0.4 times the sampling rate.
4. **Derivatives**: v from the filtered positions when the log has none (central differences),
   the accelerations from the filtered velocities (central differences).
5. **Edges**: the filter runs over the segment extended at both ends by three periods of the
   cut-off (odd extension: value and slope continue), then ``trim`` samples at each end are
   dropped (default: three periods of the cut-off, what is left of the filter's start-up).
6. **Decimation**: after filtering, every ``decimate``-th sample is kept (default: down to about
   20 times the cut-off), which keeps the information and makes the regressor smaller.
7. **Parallel filtering**: the regressor's columns pass through the same filter as the torque
   (`Segment.filtered`), so that the fit compares like with like.

Layer: methods (docs/architecture.md).
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from mechbal.identify.logs import Log, LogError

__all__ = ["Segment", "PreparedLog", "prepare", "cutoff_from_spectrum", "lowpass"]

#: filter order (Butterworth, applied forward and backward: zero phase)
FILTER_ORDER = 4


@dataclass(frozen=True)
class Segment:
    """A uniform stretch of a log at the log's own rate: time (N,), filtered q, v, a and tau
    (N, dof), the measured (unfiltered, resampled) tau, the filter (second-order sections ``sos``
    and its edge extension ``pad``) and ``keep``: the samples used (edges trimmed, decimated).
    `regressor_rows` filters the regressor's columns with the same filter as the torque
    (Gautier's parallel filtering: then ``Y(q, v, a) pi`` filtered equals ``tau`` filtered, exactly,
    whatever the frequencies of the nonlinear terms)."""

    t: np.ndarray
    q: np.ndarray
    v: np.ndarray
    a: np.ndarray
    tau: np.ndarray
    tau_measured: np.ndarray
    sos: np.ndarray
    pad: int
    keep: slice

    @property
    def samples(self) -> int:
        return len(range(*self.keep.indices(self.t.size)))

    def filtered(self, columns: np.ndarray) -> np.ndarray:
        """``columns`` (N, ...) through the segment's filter, at the kept samples."""
        shape = columns.shape
        out = lowpass(columns.reshape(shape[0], -1), self.sos, self.pad)
        return out.reshape(shape)[self.keep]


@dataclass(frozen=True)
class PreparedLog:
    """A log after `prepare`: its segments and what was done to it (``notes``, one line each)."""

    source: str
    segments: list[Segment]
    sample_rate: float
    cutoff_hz: float
    notes: list[str] = field(default_factory=list)

    @property
    def samples(self) -> int:
        return int(sum(s.samples for s in self.segments))


def lowpass(x: np.ndarray, sos: np.ndarray, pad: int = 0) -> np.ndarray:
    """Zero-phase filtering of the columns of x (N, k) by the second-order sections ``sos``,
    the ends extended by ``pad`` samples (odd extension: value and slope continue) so that the
    filter's start-up happens outside the data."""
    from scipy.signal import sosfiltfilt

    pad = min(max(int(pad), 3 * (2 * len(sos) + 1)), x.shape[0] - 1)
    return sosfiltfilt(sos, x, axis=0, padtype="odd", padlen=pad)


def _butter(cutoff_hz: float, fs: float) -> np.ndarray:
    from scipy.signal import butter

    return butter(FILTER_ORDER, cutoff_hz, btype="low", fs=fs, output="sos")


def cutoff_from_spectrum(v: np.ndarray, fs: float, *, energy: float = 0.99, factor: float = 8.0) -> float:
    """``factor`` times the frequency below which ``energy`` of the power of v (N, k) lies
    (means removed), at most 0.4 fs."""
    x = np.asarray(v, float) - np.mean(v, axis=0)
    power = np.sum(np.abs(np.fft.rfft(x, axis=0)) ** 2, axis=1)
    freqs = np.fft.rfftfreq(x.shape[0], 1.0 / fs)
    total = float(np.sum(power))
    if total <= 0.0:
        return 0.4 * fs
    k = int(np.searchsorted(np.cumsum(power) / total, energy))
    f = freqs[min(k, freqs.size - 1)]
    return float(min(max(factor * f, factor * freqs[1]), 0.4 * fs))


def _check_time(log: Log) -> None:
    t = log.t
    if t.size < 2:
        raise LogError(f"log '{log.source}': {t.size} sample(s): too few to identify anything")
    bad = np.flatnonzero(~np.isfinite(t))
    if bad.size:
        raise LogError(f"log '{log.source}': time is not finite at row {int(bad[0]) + 1}")
    dt = np.diff(t)
    back = np.flatnonzero(dt <= 0.0)
    if back.size:
        k = int(back[0])
        raise LogError(f"log '{log.source}': non-monotonic time at row {k + 2} (t = {t[k + 1]!r} s after "
                       f"{t[k]!r} s): the time must increase strictly")


def _uniform(t: np.ndarray, cols: list[np.ndarray], dt: float) -> tuple[np.ndarray, list[np.ndarray], float]:
    n = int(np.floor((t[-1] - t[0]) / dt + 1e-9)) + 1
    grid = t[0] + dt * np.arange(n)
    jitter = float(np.max(np.abs(np.diff(t) - dt)) / dt) if t.size > 1 else 0.0
    if jitter < 1e-9 and n == t.size:
        return t, cols, jitter
    out = [np.column_stack([np.interp(grid, t, c[:, j]) for j in range(c.shape[1])]) for c in cols]
    return grid, out, jitter


def prepare(log: Log, *, cutoff_hz: float | None = None, gap_factor: float = 3.0,
            trim: int | None = None, decimate: int | None = None, min_samples: int = 10) -> PreparedLog:
    """Uniform, filtered segments of ``log`` (module docstring); LogError naming the log when
    nothing usable remains."""
    _check_time(log)
    notes: list[str] = []
    parts = [log.q, log.tau] + ([log.v] if log.v is not None else [])
    finite = np.all(np.isfinite(np.hstack(parts)), axis=1)
    if not finite.all():
        notes.append(f"{int((~finite).sum())} row(s) with a non-finite value dropped")
    if finite.sum() < 2:
        raise LogError(f"log '{log.source}': no row without a non-finite value")
    t = log.t[finite]
    cols = [p[finite] for p in parts]
    dt = float(np.median(np.diff(t)))
    fs = 1.0 / dt
    steps = np.diff(t)
    cuts = np.flatnonzero(steps > gap_factor * dt)
    if cuts.size:
        notes.append(f"{cuts.size} gap(s) split the log (largest {float(steps[cuts].max()):.6g} s; "
                     f"nominal step {dt:.6g} s)")
    bounds = np.concatenate([[0], cuts + 1, [t.size]])
    pieces = []
    worst = 0.0
    for a, b in zip(bounds[:-1], bounds[1:]):
        if b - a < 2:
            continue
        tt, cc, jitter = _uniform(t[a:b], [c[a:b] for c in cols], dt)
        worst = max(worst, jitter)
        pieces.append((tt, cc))
    if worst > 1e-9:
        notes.append(f"irregular sampling resampled onto a uniform {dt:.6g} s grid (largest step "
                     f"deviation {100 * worst:.3g} % of the step)")
    has_v = log.v is not None
    if cutoff_hz is None:
        longest = max(pieces, key=lambda p: p[0].size)
        vel = longest[1][2] if has_v else np.gradient(longest[1][0], dt, axis=0)
        cutoff_hz = cutoff_from_spectrum(vel, fs)
        notes.append(f"cut-off {cutoff_hz:.4g} Hz from the spectrum (8 x the 99 % power frequency of v)")
    cutoff_hz = float(cutoff_hz)
    if not (0.0 < cutoff_hz < 0.5 * fs):
        raise LogError(f"log '{log.source}': cut-off {cutoff_hz!r} Hz must lie in (0, {0.5 * fs:.6g}) Hz "
                       f"(half the sampling rate {fs:.6g} Hz)")
    sos = _butter(cutoff_hz, fs)
    n_trim = int(np.ceil(3.0 * fs / cutoff_hz)) if trim is None else int(trim)
    step = max(1, int(fs // (20.0 * cutoff_hz))) if decimate is None else max(1, int(decimate))
    segments = []
    dropped = 0
    for tt, cc in pieces:
        if tt.size < max(2 * n_trim + min_samples, 3 * 2 * FILTER_ORDER + 1):
            dropped += 1
            continue
        pad = 3 * n_trim
        qf = lowpass(cc[0], sos, pad)
        tau_f = lowpass(cc[1], sos, pad)
        vf = lowpass(cc[2], sos, pad) if has_v else np.gradient(qf, dt, axis=0)
        af = np.gradient(vf, dt, axis=0)
        keep = slice(n_trim, tt.size - n_trim, step)
        segments.append(Segment(t=tt, q=qf, v=vf, a=af, tau=tau_f, tau_measured=cc[1], sos=sos, pad=pad,
                                keep=keep))
    if dropped:
        notes.append(f"{dropped} segment(s) shorter than {2 * n_trim + min_samples} samples dropped")
    if not segments:
        raise LogError(f"log '{log.source}': no segment of at least {2 * n_trim + min_samples} uniform samples "
                       f"(edges of {n_trim} samples are trimmed at the {cutoff_hz:.4g} Hz cut-off)")
    if n_trim:
        notes.append(f"{n_trim} samples trimmed at each end of every segment")
    if step > 1:
        notes.append(f"decimated by {step} after filtering")
    return PreparedLog(source=log.source, segments=segments, sample_rate=fs / step, cutoff_hz=cutoff_hz,
                       notes=notes)
