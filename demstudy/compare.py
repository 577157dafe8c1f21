"""TEMPORARY stand-in for the compare module (issue 12, item 1), implementing only the
contract the cost ladder uses, on identical bins: ``compare(reference, *others, fields=None,
sigma=3.0) -> list[Comparison]``. Dimensionless particle units: d = 1, m = 1, g = 1."""

from __future__ import annotations

import os
from dataclasses import dataclass, field

import numpy as np

from .io.results import Results, read_results


@dataclass
class FieldComparison:
    rel_l2: float        # ||B - A|| / ||A|| over the bins both have
    rel_l2_floor: float  # ||sigma_combined|| / ||A||: what noise alone gives
    max_z: float         # largest |B - A| / sigma_combined
    resolved: bool       # max_z > sigma
    rebinned: bool = False


@dataclass
class Comparison:
    reference: str
    other: str
    fields: dict[str, FieldComparison] = field(default_factory=dict)

    def table(self) -> str:
        lines = [f"{self.other} vs {self.reference}",
                 f"{'field':<28}{'rel_l2':>10}{'floor':>10}{'max_z':>8}  resolved"]
        for name, f in self.fields.items():
            lines.append(f"{name:<28}{f.rel_l2:>10.3g}{f.rel_l2_floor:>10.3g}"
                         f"{f.max_z:>8.2f}  {'yes' if f.resolved else 'no'}")
        return "\n".join(lines)


def _load(x: Results | str | os.PathLike) -> Results:
    return x if isinstance(x, Results) else read_results(x, skip=("frames", "collisions"))


def _field(a: np.ndarray, ea: np.ndarray, b: np.ndarray, eb: np.ndarray,
           sigma: float) -> FieldComparison | None:
    ok = np.isfinite(a) & np.isfinite(b) & np.isfinite(ea) & np.isfinite(eb)
    if not ok.any():
        return None
    diff, err = (b - a)[ok], np.hypot(ea, eb)[ok]
    norm = float(np.linalg.norm(a[ok])) or 1.0
    z = np.abs(diff) / np.where(err > 0, err, np.inf)
    max_z = float(z.max()) if z.size else 0.0
    return FieldComparison(float(np.linalg.norm(diff)) / norm,
                           float(np.linalg.norm(err)) / norm, max_z, max_z > sigma)


def compare(reference, *others, fields=None, sigma: float = 3.0) -> list[Comparison]:
    ref = _load(reference)
    out = []
    for other in others:
        res = _load(other)
        names = fields or [k for k in ref.profiles if f"{k}_err" in ref.profiles]
        comp = Comparison(str(ref.path), str(res.path))
        for name in names:
            if f"{name}_err" not in res.profiles or name not in res.profiles:
                continue
            a, b = np.asarray(ref.profiles[name], float), np.asarray(res.profiles[name], float)
            if a.shape != b.shape:
                continue  # the stand-in does not rebin
            fc = _field(a, np.asarray(ref.profiles[f"{name}_err"], float), b,
                        np.asarray(res.profiles[f"{name}_err"], float), sigma)
            if fc is not None:
                comp.fields[name] = fc
        out.append(comp)
    return out
