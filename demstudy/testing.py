"""Comparisons of results within their statistical errors, for pytest files.

Dimensionless particle units: d = 1, m = 1, g = 1 when gravity acts.

    import demstudy as ds
    from demstudy.testing import assert_profiles_agree

    def test_soft_contacts_reach_the_hard_limit():
        scene = ds.load_scene("shear/lees-edwards-2d", run={"production": 20})
        hard, soft = ds.run(scene, engine="edmd"), ds.run(scene, engine="lammps")
        assert_profiles_agree(hard, soft, fields=["solid_fraction", "temperature"])

The test is :mod:`demstudy.comparison.stats` (shared with ``demstudy compare``, which also
rebins and summarises whole fields). Each bin's difference is divided by its combined
standard error √(σ_a² + σ_b²). The
comparison as a whole fails with the probability of a two-sided ``sigma``-σ event (0.27 % at
3σ) when the two runs sample the same state: with n compared values each one is held to the
Šidák-corrected level, so a profile of 40 bins does not fail by chance one time in ten. The
errors are estimates, so each difference is judged against Student's t with the
Welch–Satterthwaite degrees of freedom (max(1, min(n_blocks, effective_samples) − 1) per
run), not the normal distribution: with 20 blocks a 3σ-normal test would fail several times
too often. Bins with nothing to compare are left out and counted: values
or errors not finite, or both errors zero with equal values (an empty bin: ν = 0 ± 0 in both).
On failure the ``AssertionError`` carries a table of every disagreeing bin. The errors are
the profiles' own; they are only as good as the blocking behind them (docs/results-format.md).
Runs must share their bins: servo runs lay them where the walls stand when production
starts, so two servo runs are compared on their own bins only when those coincide.
"""

from __future__ import annotations

import math
import os
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import NamedTuple

import numpy as np

from .comparison.stats import block_dof, sidak_level, z_test
from .io.results import Results, read_results

__all__ = ["ProfileComparison", "Row", "assert_profiles_agree", "compare_profiles"]

DEFAULT_FIELDS = ("solid_fraction", "velocity", "temperature")


class Row(NamedTuple):
    """One compared value: field (component), bin (0-based), y, both runs' values and
    errors, z = Δ/√(σ_a² + σ_b²), the degrees of freedom of that ratio and its two-sided
    p-value."""

    field: str
    bin: int
    y: float
    a: float
    err_a: float
    b: float
    err_b: float
    z: float
    dof: float
    p: float


@dataclass
class ProfileComparison:
    """The outcome of :func:`compare_profiles`: one row per compared value."""

    sigma: float  # the requested significance, in σ of one two-sided normal test
    each: float  # the p-value each row is held to after the multiple-comparison correction
    rows: list[Row] = field(default_factory=list)
    skipped: int = 0  # values left out (nothing to compare)

    @property
    def worst(self) -> float:
        """The largest |z|."""
        return max((abs(r.z) for r in self.rows), default=0.0)

    @property
    def smallest_p(self) -> float:
        return min((r.p for r in self.rows), default=1.0)

    @property
    def ok(self) -> bool:
        return self.smallest_p >= self.each

    def table(self, only_failing: bool = True) -> str:
        head = (f"{'field':<26} {'bin':>4} {'y':>8} {'a':>12} {'±':>9} {'b':>12} {'±':>9} "
                f"{'z':>7} {'p':>9}")
        lines = [head, "-" * len(head)]
        for r in self.rows:
            if only_failing and r.p >= self.each:
                continue
            lines.append(f"{r.field:<26} {r.bin + 1:>4} {r.y:>8.3g} {r.a:>12.5g} "
                         f"{r.err_a:>9.2g} {r.b:>12.5g} {r.err_b:>9.2g} {r.z:>7.2f} "
                         f"{r.p:>9.2g}")
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
    # degrees of freedom of each run's errors (comparison.stats.block_dof)
    dof_a, dof_b = (block_dof(r.profile_attrs) for r in (ra, rb))
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
                a, sa, b, sb = va[i, k], ea[i, k], vb[i, k], eb[i, k]
                empty = sa == 0 and sb == 0 and a == b
                if not dense[i] or not all(map(math.isfinite, (a, sa, b, sb))) or empty:
                    skipped += 1
                    continue
                rows.append(_row(label, i, float(y[i]), a, sa, b, sb, dof_a, dof_b))
    each = sidak_level(sigma, len(rows))
    return ProfileComparison(sigma, each, rows, skipped)


def _row(label: str, i: int, y: float, a: float, sa: float, b: float, sb: float,
         dof_a: float, dof_b: float) -> Row:
    """One compared value, its z-score and two-sided p-value
    (:func:`demstudy.comparison.stats.z_test`)."""
    z, dof, p = (float(v) for v in z_test(a - b, sa, sb, dof_a, dof_b))
    return Row(label, i, y, a, sa, b, sb, z, dof, p)


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
            f"profiles disagree: p = {result.smallest_p:.2g} < {result.each:.2g} (|z| up to "
            f"{result.worst:.2f}; {sigma:g}σ over {len(result.rows)} values, Šidák-corrected, "
            f"Student's t)\na = {_label(ra)}, b = {_label(rb)}\n{result.table()}")
    return result
