"""Comparisons of results within their statistical errors, for pytest files.

Dimensionless particle units: d = 1, m = 1, g = 1 when gravity acts.

    import demstudy as ds
    from demstudy.testing import assert_profiles_agree

    def test_soft_contacts_reach_the_hard_limit():
        scene = ds.load_scene("shear/lees-edwards-2d", run={"production": 20})
        hard, soft = ds.run(scene, engine="edmd"), ds.run(scene, engine="lammps")
        assert_profiles_agree(hard, soft, fields=["solid_fraction", "temperature"])

Each bin's difference is divided by its combined standard error √(σ_a² + σ_b²). The
comparison as a whole fails with the probability of a two-sided ``sigma``-σ event (0.27 % at
3σ) when the two runs sample the same state: with n compared values each one is held to the
Šidák-corrected level, so a profile of 40 bins does not fail by chance one time in ten.
Bins whose values or errors are not finite (empty bins) are left out and counted. On failure
the ``AssertionError`` carries a table of every disagreeing bin. The errors are the profiles'
own (blocking over time); they are only as good as those (docs/results-format.md).
"""

from __future__ import annotations

import math
import os
from collections.abc import Sequence
from dataclasses import dataclass, field

import numpy as np
from scipy.special import erfcinv

from .io.results import Results, read_results

__all__ = ["ProfileComparison", "assert_profiles_agree", "compare_profiles"]

DEFAULT_FIELDS = ("solid_fraction", "velocity", "temperature")


@dataclass
class ProfileComparison:
    """The outcome of :func:`compare_profiles`: one row per compared value."""

    sigma: float  # the requested significance, in σ of one two-sided test
    threshold: float  # what each |z| is held to after the multiple-comparison correction
    rows: list[tuple] = field(default_factory=list)  # (field, bin, y, a, err_a, b, err_b, z)
    skipped: int = 0  # values left out (not finite in either run)

    @property
    def worst(self) -> float:
        return max((abs(r[-1]) for r in self.rows), default=0.0)

    @property
    def ok(self) -> bool:
        return self.worst <= self.threshold

    def table(self, only_failing: bool = True) -> str:
        head = (f"{'field':<26} {'bin':>4} {'y':>8} {'a':>12} {'±':>9} {'b':>12} {'±':>9} "
                f"{'z':>7}")
        lines = [head, "-" * len(head)]
        for name, b, y, a, ea, bv, eb, z in self.rows:
            if only_failing and abs(z) <= self.threshold:
                continue
            lines.append(f"{name:<26} {b + 1:>4} {y:>8.3g} {a:>12.5g} {ea:>9.2g} {bv:>12.5g} "
                         f"{eb:>9.2g} {z:>7.2f}")
        return "\n".join(lines)


def _results(source: Results | str | os.PathLike) -> Results:
    return source if isinstance(source, Results) else read_results(source)


def _label(res: Results) -> str:
    return f"{res.attrs.get('scene_name', '?')} ({res.attrs.get('engine', '?')})"


def compare_profiles(a: Results | str | os.PathLike, b: Results | str | os.PathLike,
                     fields: Sequence[str] = DEFAULT_FIELDS, sigma: float = 3.0,
                     min_solid_fraction: float = 0.0) -> ProfileComparison:
    """Per-bin z-scores of ``fields`` between two runs' profiles (see the module docstring).

    The runs must use the same bins along the same axis (``ValueError`` otherwise). Vector
    fields (``velocity``, ``temperature_components``) compare component by component.
    ``min_solid_fraction``: leave out bins where either run is more dilute than this."""
    ra, rb = _results(a), _results(b)
    pa, pb = ra.profiles, rb.profiles
    for res, prof in ((ra, pa), (rb, pb)):
        if not prof or "edges" not in prof:
            raise ValueError(f"{_label(res)}: no profiles to compare")
    if pa["edges"].shape != pb["edges"].shape or not np.allclose(pa["edges"], pb["edges"],
                                                                  rtol=1e-9, atol=1e-9):
        raise ValueError(f"the runs use different bins: {_label(ra)} has "
                         f"{len(pa['edges']) - 1} from {pa['edges'][0]:g} to "
                         f"{pa['edges'][-1]:g}, {_label(rb)} {len(pb['edges']) - 1} from "
                         f"{pb['edges'][0]:g} to {pb['edges'][-1]:g}")
    dense = np.ones(len(pa["edges"]) - 1, bool)
    if min_solid_fraction > 0:
        dense = (pa["solid_fraction"] >= min_solid_fraction) & \
                (pb["solid_fraction"] >= min_solid_fraction)
    y = pa.get("y", 0.5 * (pa["edges"][1:] + pa["edges"][:-1]))
    rows, skipped = [], 0
    for name in fields:
        missing = [_label(r) for r, p in ((ra, pa), (rb, pb))
                   if name not in p or f"{name}_err" not in p]
        if missing:
            raise ValueError(f"profile {name!r} with its error {name}_err is missing in "
                             f"{', '.join(missing)}")
        va, vb = np.asarray(pa[name], float), np.asarray(pb[name], float)
        ea, eb = np.asarray(pa[f"{name}_err"], float), np.asarray(pb[f"{name}_err"], float)
        va, vb, ea, eb = (v.reshape(len(y), -1) for v in (va, vb, ea, eb))
        for k in range(va.shape[1]):
            label = name if va.shape[1] == 1 else f"{name}[{'xyz'[k]}]"
            for i in range(len(y)):
                values = (va[i, k], ea[i, k], vb[i, k], eb[i, k])
                if not dense[i] or not all(map(math.isfinite, values)):
                    skipped += 1
                    continue
                combined = math.hypot(ea[i, k], eb[i, k])
                diff = va[i, k] - vb[i, k]
                z = diff / combined if combined > 0 else (0.0 if diff == 0 else math.inf)
                rows.append((label, i, float(y[i]), va[i, k], ea[i, k], vb[i, k], eb[i, k], z))
    # Šidák: each of n tests at 1 − (1 − p)^(1/n) keeps the family's false alarms at p
    p = math.erfc(sigma / math.sqrt(2.0))
    n = max(1, len(rows))
    each = -math.expm1(math.log1p(-p) / n)
    threshold = float(math.sqrt(2.0) * erfcinv(each))
    return ProfileComparison(sigma, threshold, rows, skipped)


def assert_profiles_agree(a: Results | str | os.PathLike, b: Results | str | os.PathLike,
                          fields: Sequence[str] = DEFAULT_FIELDS, sigma: float = 3.0,
                          min_solid_fraction: float = 0.0) -> ProfileComparison:
    """Assert that two runs' profiles agree within their combined statistical errors
    (:func:`compare_profiles`); on failure the message tables every disagreeing bin."""
    result = compare_profiles(a, b, fields, sigma, min_solid_fraction)
    if not result.rows:
        raise AssertionError("nothing to compare: every bin was empty or without an error")
    if not result.ok:
        ra, rb = _results(a), _results(b)
        raise AssertionError(
            f"profiles disagree: |z| up to {result.worst:.2f} > {result.threshold:.2f} "
            f"({sigma:g}σ over {len(result.rows)} values, Šidák-corrected)\n"
            f"a = {_label(ra)}, b = {_label(rb)}\n{result.table()}")
    return result
