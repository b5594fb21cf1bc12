"""Results of a sweep: the table (a pandas DataFrame, one row per evaluation), summary statistics,
files (Parquet through pyarrow, or CSV) and plots (tornado chart of a sensitivity sweep,
histograms of a Monte Carlo sweep).

Layer: methods (docs/architecture.md)."""
from __future__ import annotations

import math
from pathlib import Path
from typing import Any

import numpy as np

from mechbal.sweep.backends import require_extra
from mechbal.sweep.metrics import UNITS

#: Monte Carlo quantiles of the summary
QUANTILES = (0.05, 0.5, 0.95)


def _finite(x) -> float | None:
    x = float(x)
    return x if math.isfinite(x) else None


class SweepResult:
    """``table``: DataFrame with ``evaluation`` (0 ..), for a sensitivity sweep ``parameter`` and
    ``level``, one column per parameter path (its value), one per metric, and ``status`` ("ok"
    or why the set could not be evaluated: its metrics are NaN). ``nominal``: the metrics of the
    nominal mechanism. ``kind``, ``paths``, ``metric_columns``, ``name``, ``title``, ``seed``."""

    def __init__(self, table, nominal: dict[str, float], *, kind: str, paths: list[str],
                 metric_columns: list[str], name: str, title: str = "", seed: int = 0,
                 units: dict[str, str] | None = None, settings: dict | None = None):
        self.table = table
        self.nominal = nominal
        self.kind = kind
        self.paths = paths
        self.metric_columns = metric_columns
        self.name, self.title, self.seed = name, title, seed
        self.units = units or {}
        self.settings = settings or {}

    @classmethod
    def assemble(cls, sweep, plan, values: np.ndarray, labels: dict, results: list[dict],
                 nominal_result: dict) -> "SweepResult":
        pd = require_extra("pandas")
        results = sorted(results, key=lambda r: r["start"])
        columns = plan.columns
        data: dict[str, Any] = {"evaluation": np.arange(len(values), dtype=np.int64)}
        for k, v in labels.items():
            data[k] = v
        for i, p in enumerate(plan.paths):
            data[p] = values[:, i]
        for c in columns:
            data[c] = np.concatenate([r["columns"][c] for r in results]) if results else np.zeros(0)
        data["status"] = [s for r in results for s in r["status"]]
        table = pd.DataFrame(data)
        nominal = {c: float(nominal_result["columns"][c][0]) for c in columns}
        units = {}
        for m in plan.metrics:
            if m.builtin:
                units[m.name] = UNITS[f"{m.statistic}_{m.quantity}"]
        settings = {"case": sweep.base.name, "evaluations": int(len(values)),
                    "chunk_size": sweep.default_chunk_size(),
                    "poses": None if sweep.poses is None else int(len(sweep.poses)),
                    "trajectory_samples": None if sweep.trajectory is None else int(len(sweep.trajectory[0])),
                    "parameters": [{"path": p.path, "nominal": p.nominal, "law": p.law,
                                    **({"lower": p.lower, "upper": p.upper} if p.law == "uniform" else {}),
                                    **({"mean": p.mean, "std": p.std} if p.law == "normal" else {}),
                                    **({"values": list(p.values)} if p.law == "list" else {}),
                                    "batched": p.target.batched} for p in sweep.parameters]}
        return cls(table, nominal, kind=sweep.kind, paths=plan.paths, metric_columns=columns,
                   name=sweep.name, title=sweep.title, seed=sweep.seed, units=units, settings=settings)

    # ---- statistics -----------------------------------------------------------------------------
    def summary(self) -> dict[str, Any]:
        """Plain JSON-able summary: per metric the nominal value and the statistics of the kind
        (Monte Carlo: mean, std, min, quantiles, max, relative change of the mean and the 95th
        percentile; sensitivity: each parameter's low and high results and swing, largest first;
        grid: min and max and the parameter values where they are)."""
        t = self.table
        ok = t["status"] == "ok"
        out: dict[str, Any] = {"sweep": self.name, "title": self.title, "kind": self.kind, "seed": self.seed,
                               **self.settings, "failed_evaluations": int((~ok).sum()),
                               "units": self.units, "metrics": {}}
        failures = t.loc[~ok, "status"].value_counts().head(5)
        if len(failures):
            out["failure_reasons"] = {str(k): int(v) for k, v in failures.items()}
        for c in self.metric_columns:
            x = t.loc[ok, c].to_numpy(dtype=float)
            x = x[np.isfinite(x)]
            entry: dict[str, Any] = {"nominal": _finite(self.nominal.get(c, math.nan))}
            if self.kind == "monte_carlo" and x.size:
                q = np.quantile(x, QUANTILES)
                entry.update(mean=float(x.mean()), std=float(x.std(ddof=1)) if x.size > 1 else 0.0,
                             min=float(x.min()), max=float(x.max()),
                             **{f"p{int(round(100 * a)):02d}": float(v) for a, v in zip(QUANTILES, q)})
            elif self.kind == "sensitivity":
                entry["parameters"] = self.sensitivity(c)
            elif x.size:
                i_min, i_max = int(t.loc[ok, c].idxmin()), int(t.loc[ok, c].idxmax())
                entry.update(min=float(t.at[i_min, c]), max=float(t.at[i_max, c]),
                             at_min={p: float(t.at[i_min, p]) for p in self.paths},
                             at_max={p: float(t.at[i_max, p]) for p in self.paths})
            out["metrics"][c] = entry
        return out

    def sensitivity(self, column: str) -> list[dict[str, Any]]:
        """Per parameter of a sensitivity sweep: values at the low and high ends, the metric there,
        its ``swing`` |high - low| and its ``effect`` (the larger change from the nominal value,
        which is what matters when the nominal is an optimum: a balanced arm's peak torque grows
        at both ends), largest effect first."""
        t = self.table
        nominal = self.nominal.get(column, math.nan)
        rows = []
        for p in self.paths:
            sub = t[t["parameter"] == p].set_index("level")
            low, high = float(sub.at["low", column]), float(sub.at["high", column])
            rows.append({"parameter": p, "low_value": float(sub.at["low", p]),
                         "high_value": float(sub.at["high", p]), "at_low": _finite(low),
                         "at_high": _finite(high),
                         "swing": _finite(abs(high - low)) if math.isfinite(high - low) else None,
                         "effect": _finite(max(abs(low - nominal), abs(high - nominal)))
                         if math.isfinite(low - nominal) and math.isfinite(high - nominal) else None})
        rows.sort(key=lambda r: -(r["effect"] if r["effect"] is not None else -1.0))
        return rows

    # ---- files ------------------------------------------------------------------------------------
    def write_table(self, path: str | Path, fmt: str | None = None) -> Path:
        """The table as Parquet (pyarrow) or CSV (by ``fmt`` or the file's suffix)."""
        path = Path(path)
        fmt = fmt or ("csv" if path.suffix.lower() == ".csv" else "parquet")
        if fmt == "csv":
            self.table.to_csv(path, index=False, float_format="%.17g")
        else:
            require_extra("pyarrow")
            self.table.to_parquet(path, index=False, engine="pyarrow")
        return path

    def write(self, out: str | Path, fmt: str = "parquet") -> list[Path]:
        """``out``/results.parquet (or .csv), summary.json and the plots; returns the files."""
        from mechbal.export import write_summary

        out = Path(out)
        out.mkdir(parents=True, exist_ok=True)
        files = [self.write_table(out / f"results.{'csv' if fmt == 'csv' else 'parquet'}", fmt)]
        files += self.plot(out)
        files.append(write_summary(out / "summary.json", self.summary(), command="sweep"))
        return files

    # ---- plots ------------------------------------------------------------------------------------
    def plot(self, out: str | Path) -> list[Path]:
        """Tornado charts (sensitivity: one per metric), histograms (Monte Carlo: one figure), none
        for a grid. Returns the files written."""
        out = Path(out)
        if self.kind == "sensitivity":
            return [self.plot_tornado(out / f"tornado_{_safe(c)}.png", c) for c in self.metric_columns]
        if self.kind == "monte_carlo":
            return [self.plot_histograms(out / "histograms.png")]
        return []

    def _label(self, c: str) -> str:
        base = c.split(".", 1)[0]
        return f"{c} [{self.units[base]}]" if base in self.units else c

    def plot_tornado(self, path: str | Path, column: str) -> Path:
        """Tornado chart: for each parameter (largest swing on top) the change of ``column`` from
        its nominal value with the parameter at the low end (one bar) and the high end (the other)."""
        from mechbal.report import _finish, _pyplot

        plt = _pyplot()
        rows = self.sensitivity(column)[::-1]
        nominal = self.nominal.get(column, math.nan)
        fig, ax = plt.subplots(figsize=(8, 1.2 + 0.45 * len(rows)))
        y = np.arange(len(rows))
        lo = np.array([np.nan if r["at_low"] is None else r["at_low"] - nominal for r in rows])
        hi = np.array([np.nan if r["at_high"] is None else r["at_high"] - nominal for r in rows])
        ax.barh(y - 0.18, lo, height=0.36, color="tab:blue", label="parameter at its low end")
        ax.barh(y + 0.18, hi, height=0.36, color="tab:orange", label="parameter at its high end")
        ax.axvline(0.0, color="k", lw=0.8)
        ax.set_yticks(y)
        ax.set_yticklabels([f"{r['parameter']}\n{r['low_value']:.4g} .. {r['high_value']:.4g}" for r in rows],
                           fontsize=7)
        ax.set_xlabel(f"change of {self._label(column)} from its nominal value {nominal:.4g}", fontsize=9)
        return _finish(plt, fig, [ax], path, f"{self.title or self.name}: sensitivity of {column}",
                       "Each parameter alone at the low and the high end of its range (values under its "
                       "name), every other parameter nominal; largest effect on top.")

    def plot_histograms(self, path: str | Path) -> Path:
        """One histogram per metric of a Monte Carlo sweep, the nominal value marked."""
        from mechbal.report import _finish, _pyplot, grid_shape

        plt = _pyplot()
        ok = self.table["status"] == "ok"
        rows, cols = grid_shape(len(self.metric_columns))
        fig, axes = plt.subplots(rows, cols, figsize=(4.2 * cols, 3.2 * rows), squeeze=False)
        for ax, c in zip(axes.flat, self.metric_columns):
            x = self.table.loc[ok, c].to_numpy(dtype=float)
            x = x[np.isfinite(x)]
            ax.hist(x, bins=min(60, max(10, int(np.sqrt(max(1, x.size))))), color="tab:blue", alpha=0.8)
            n = self.nominal.get(c, math.nan)
            if math.isfinite(n):
                ax.axvline(n, color="k", ls="--", lw=1)
                ax.set_title(f"nominal {n:.4g}", fontsize=8)
            ax.set_xlabel(self._label(c), fontsize=8)
            ax.set_ylabel("evaluations", fontsize=8)
        for ax in list(axes.flat)[len(self.metric_columns):]:
            ax.axis("off")
        failed = int((~ok).sum())
        return _finish(plt, fig, list(axes.flat), path,
                       f"{self.title or self.name}: {len(self.table)} evaluations (seed {self.seed})",
                       "Monte Carlo distribution of each metric over the parameter sets (dashed: the nominal "
                       f"mechanism){f'; {failed} sets could not be evaluated and are left out' if failed else ''}.")


def _safe(name: str) -> str:
    return "".join(c if c.isalnum() or c in "-_" else "_" for c in name)


__all__ = ["SweepResult"]
