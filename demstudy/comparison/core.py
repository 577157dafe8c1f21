"""``demstudy compare``: profiles and stresses of runs against a reference run, bin by bin
with their combined statistical errors, summarised per field.

Dimensionless particle units: d = 1, m = 1, g = 1 when gravity acts (otherwise a wall speed
or the shear rate sets the time scale); every compared quantity keeps the units of its
results file (docs/results-format.md).

Per bin: Δ = other − reference, σ_Δ = √(σ_ref² + σ_other²), z = Δ/σ_Δ. Per field, over the
bins both runs populate (empty bins, values without a finite error and bins more dilute than
``min_solid_fraction`` are left out and counted): the relative L2 error ‖Δ‖/‖ref‖, its noise
floor √(Σσ_Δ²)/‖ref‖ (what the statistical errors alone give: two runs of one state have
‖Δ‖ ≈ the floor), the debiased estimate √(max(0, ‖Δ‖² − Σσ_Δ²))/‖ref‖, the largest |z| and
whether the difference is resolved at all: the smallest p-value (Student's t on the blocks'
degrees of freedom) below the Šidák-corrected level that makes the field's family fail at
the rate of one ``sigma``-σ event (:mod:`demstudy.comparison.stats`, the test of
``demstudy.testing``). An unresolved difference is reported as agreement within the noise
floor, not as zero. Runs on different bins are moved to a common grid first
(:mod:`demstudy.comparison.rebin`), and the comparison says so.
"""

from __future__ import annotations

import math
import os
import tomllib
from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ..errors import NotComparable
from ..io.results import Results, read_results
from .rebin import common_grid, rebin_profiles, rebin_stress, splits_bins
from .stats import block_dof, dof_note, sidak_level, z_test

__all__ = ["Comparison", "FieldComparison", "compare", "field_names"]

#: fields first in tables and figures (the rest follow in their stored order)
FIRST = ("solid_fraction", "velocity", "temperature", "temperature_components",
         "rotational_temperature", "stress")
AXES = "xyz"
#: relative error (and difference) below which a field is known exactly in both runs: its
#: errors are round-off (the mean mass of equal particles), its rows would be noise
EXACT = 1e-12


@dataclass(frozen=True)
class FieldComparison:
    """One field (a profile, a component of a vector profile, ``stress/xy`` of the total
    stress tensor) of one run against the reference, on the common bins ``y``. Arrays cover
    every common bin; ``compared`` marks those that entered the summary."""

    name: str
    y: np.ndarray
    reference: np.ndarray
    reference_err: np.ndarray
    other: np.ndarray
    other_err: np.ndarray
    delta: np.ndarray
    delta_err: np.ndarray
    rel_l2: float  # ‖Δ‖/‖ref‖ over the compared bins
    rel_l2_floor: float  # √(Σσ_Δ²)/‖ref‖: what the statistical errors alone give
    max_z: float  # largest |Δ|/σ_Δ
    resolved: bool  # a difference beyond the statistical errors (family test at sigma)
    rebinned: bool
    rel_l2_debiased: float = math.nan  # √(max(0, ‖Δ‖² − Σσ_Δ²))/‖ref‖
    p: float = 1.0  # smallest two-sided p-value over the compared bins
    level: float = 0.0  # the p-value each bin is held to (Šidák)
    compared: np.ndarray | None = None  # bool per bin
    reference_is_zero: bool = False  # ‖ref‖ within 2× its own noise: rel. L2 not meaningful
    units: str = ""

    @property
    def n_compared(self) -> int:
        return int(np.sum(self.compared)) if self.compared is not None else len(self.y)

    @property
    def verdict(self) -> str:
        if self.n_compared == 0:
            return "nothing to compare"
        if self.resolved:
            return (f"DIFFERS: rel. L2 {self.rel_l2_debiased:.3g} beyond noise "
                    f"(p = {self.p:.2g} < {self.level:.2g})")
        if self.reference_is_zero:  # a relative bound means nothing: the absolute one
            err = self.delta_err if self.compared is None else self.delta_err[self.compared]
            rms = float(np.sqrt(np.mean(err**2)))
            return f"agrees within errors (rms Δ ≲ {rms:.2g} {self.units})"
        # the noise floor bounds the difference; a field whose bins all moved a little
        # (not resolved bin by bin) can lie above it: the larger of the two then, flagged
        bound = max(self.rel_l2_floor, self.rel_l2)
        shared = self.rel_l2 / self.rel_l2_floor if self.rel_l2_floor > 0 else 0.0
        flag = f"; {shared:.1f}× the floor: a shift shared by the bins?" if shared > 2 else ""
        return f"agrees within errors (rel. L2 ≲ {bound:.3g}{flag})"


@dataclass
class Comparison:
    """One run (``other``) against the reference: every compared field, and notes on what
    was done to compare them (rebinning, bins left out, differing engines)."""

    reference: str
    other: str
    fields: dict[str, FieldComparison]
    notes: list[str] = field(default_factory=list)
    sigma: float = 3.0
    rebinned: bool = False

    @property
    def resolved(self) -> list[str]:
        """The fields whose difference is beyond the statistical errors."""
        return [name for name, f in self.fields.items() if f.resolved]

    def table(self) -> str:
        """One row per field: compared bins, relative L2 error, its noise floor and debiased
        value, the largest |z| and the verdict; then the notes."""
        head = (f"{'field':<28} {'bins':>7} {'rel.L2':>8} {'floor':>8} {'debiased':>8} "
                f"{'max|z|':>7}  verdict ({self.sigma:g}σ family per field)")
        title = f"reference: {self.reference}\nother:     {self.other}" + \
            ("   [rebinned to a common grid]" if self.rebinned else "")
        lines = [title, head, "-" * len(head)]
        for f in self.fields.values():
            star = "*" if f.reference_is_zero else " "
            lines.append(f"{f.name:<28} {f.n_compared:>3}/{len(f.y):<3} {f.rel_l2:>7.3g}{star} "
                         f"{f.rel_l2_floor:>8.3g} {f.rel_l2_debiased:>8.3g} {f.max_z:>7.2f}  "
                         f"{f.verdict}")
        if any(f.reference_is_zero for f in self.fields.values()):
            lines.append("* the reference is zero within its errors: its relative L2 is "
                         "not meaningful (see Δ in the figure)")
        lines += [f"note: {n}" for n in self.notes]
        return "\n".join(lines)


# -- loading -------------------------------------------------------------------------------
def _load(source: Results | str | os.PathLike) -> Results:
    if isinstance(source, Results):
        return source
    path = Path(source)
    if not path.is_file():
        raise NotComparable(f"{path}: no such results file")
    return read_results(path, skip=("frames", "collisions"))


def _brace(names: Sequence[str]) -> str:
    """Replica files in shell brace form: ``a-r{0,1,2}.h5``, ``a{,-r1,-r2}.h5`` (the full list
    when they share nothing)."""
    prefix = os.path.commonprefix(list(names))
    rest = [n[len(prefix):] for n in names]
    suffix = os.path.commonprefix([r[::-1] for r in rest])[::-1]
    middle = [r[:len(r) - len(suffix)] for r in rest]
    if not (prefix or suffix) or len(set(middle)) < len(middle):
        return ",".join(names)
    return f"{prefix}{{{','.join(middle)}}}{suffix}"


def _label(res: Results) -> str:
    engine = res.attrs.get("engine", "?")
    if res.profile_attrs.get("error_method") == "replicas":  # a replica mean
        files = str(res.attrs.get("replica_files", "?")).split(",")
        return f"{_brace(files)} ({engine}, mean of {res.profile_attrs.get('replicas')} " \
               "replicas)"
    name = res.path.name if res.path is not None else res.attrs.get("scene_name", "?")
    return f"{name} ({engine})"


def _replica_note(res: Results, role: str) -> str | None:
    """What the table says of a replica mean: its errors come from the replicas' scatter."""
    if res.profile_attrs.get("error_method") != "replicas":
        return None
    r = int(res.profile_attrs.get("replicas", 0))
    ratio = float(res.profile_attrs.get("scatter_to_quoted_error", math.nan))
    return (f"{role}: mean of {r} replicas (other seeds); errors: the standard error across "
            f"them (std/√{r}, {r - 1} degrees of freedom)" +
            (f"; they scatter {ratio:.2g}× their own quoted errors (median over fields)"
             if math.isfinite(ratio) else ""))


def _load_group(source) -> Results:
    """A run, or a list of replicas of one run (combined: ``combine_replicas``)."""
    if isinstance(source, list | tuple):
        if len(source) == 1:
            return _load(source[0])
        from .replicas import combine_replicas

        return combine_replicas(source)
    return _load(source)


def _dim(res: Results) -> int | None:
    dim = res.profile_attrs.get("dim")
    if dim is None and isinstance(res.attrs.get("scene_toml"), str):
        dim = tomllib.loads(res.attrs["scene_toml"]).get("dimension")
    return int(dim) if dim else None


def _stress(res: Results) -> dict[str, np.ndarray] | None:
    for key in ("stress", "statistics/stress"):
        group = res.groups.get(key)
        if group and "total" in group and "total_err" in group and "edges" in group:
            return group
    return None


def _soft(res: Results) -> str | None:
    text = res.attrs.get("scene_toml")
    if res.attrs.get("engine") in (None, "edmd") or not isinstance(text, str):
        return None
    soft = tomllib.loads(text).get("soft", {})
    return f"{soft.get('model', '?')} {soft.get('hardness', '?')}, " \
           f"{soft.get('steps_per_contact', '?')} steps per contact"


# -- fields --------------------------------------------------------------------------------
def _split_fields(prof: dict[str, np.ndarray], stress: dict[str, np.ndarray] | None
                  ) -> dict[str, tuple[np.ndarray, np.ndarray, str]]:
    """label → (values, errors, dataset): vector profiles by component (``velocity[x]``),
    the total stress tensor by component (``stress/xy``, upper triangle)."""
    out: dict[str, tuple[np.ndarray, np.ndarray, str]] = {}
    for name, value in prof.items():
        if name in ("edges", "y") or name.endswith("_err") or f"{name}_err" not in prof:
            continue
        q, e = np.asarray(value, float), np.asarray(prof[f"{name}_err"], float)
        if q.ndim == 2 and q.shape[1] > 1:
            for k in range(q.shape[1]):
                out[f"{name}[{AXES[k]}]"] = q[:, k], e[:, k], name
        else:
            out[name] = q.reshape(q.shape[:1]) if q.ndim else q.reshape(1), \
                e.reshape(e.shape[:1]) if e.ndim else e.reshape(1), name
    if stress is not None:
        q, e = np.asarray(stress["total"], float), np.asarray(stress["total_err"], float)
        for a in range(q.shape[1]):
            for b in range(a, q.shape[1]):
                out[f"stress/{AXES[a]}{AXES[b]}"] = q[:, a, b], e[:, a, b], "stress"
    return out


def _order(names: Sequence[str], datasets: dict[str, str]) -> list[str]:
    rank = {n: (FIRST.index(datasets[n]) if datasets[n] in FIRST else len(FIRST), i)
            for i, n in enumerate(names)}
    return sorted(names, key=rank.__getitem__)


def field_names(source: Results | str | os.PathLike) -> list[str]:
    """The fields a run offers for comparison (profile components and ``stress/..``)."""
    res = _load(source)
    split = _split_fields(res.profiles, _stress(res))
    return _order(list(split), {k: v[2] for k, v in split.items()})


def _select(requested: Sequence[str] | None, ref: dict, other: dict, labels: tuple[str, str],
            notes: list[str]) -> list[str]:
    """The compared labels: every field of both runs, or those ``requested`` (a label, or a
    dataset name standing for all its components, ``velocity`` or ``stress``)."""
    datasets = {k: v[2] for k, v in {**other, **ref}.items()}
    if requested is None:
        shared = [n for n in ref if n in other]
        only = sorted(set(ref) ^ set(other))
        if only:
            notes.append(f"not in both runs, not compared: {', '.join(only)}")
        return _order(shared, datasets)
    chosen: list[str] = []
    for want in requested:
        match = [n for n in datasets if n == want or datasets[n] == want]
        if not match:
            raise NotComparable(f"unknown field {want!r} (available: "
                             f"{', '.join(_order(list(datasets), datasets))}; or a dataset "
                             f"name for all its components, e.g. velocity, stress)")
        for n in match:
            lacking = [lab for lab, run in zip(labels, (ref, other), strict=True)
                       if n not in run]
            if lacking:
                raise NotComparable(f"field {n!r} is not in {' and '.join(lacking)}")
        chosen += [n for n in match if n not in chosen]
    return chosen


# -- the comparison ------------------------------------------------------------------------
def _exact(r: np.ndarray, er: np.ndarray, o: np.ndarray, eo: np.ndarray) -> bool:
    """Both runs know the field to round-off and agree to it (module constant ``EXACT``):
    every bin with a finite value has errors ≤ EXACT × |value| in both runs and
    |Δ| ≤ EXACT × max |value|."""
    with np.errstate(invalid="ignore"):
        have = np.isfinite(r) & np.isfinite(o)
        if not have.any():
            return False
        r, er, o, eo = r[have], er[have], o[have], eo[have]
        scale = np.maximum(np.abs(r), np.abs(o))
        return bool(np.all(np.abs(er) <= EXACT * np.abs(r))
                    and np.all(np.abs(eo) <= EXACT * np.abs(o))
                    and np.all(np.abs(o - r) <= EXACT * scale))


def _field(name: str, y: np.ndarray, r: np.ndarray, er: np.ndarray, o: np.ndarray,
           eo: np.ndarray, dense: np.ndarray, dofs: tuple[float, float], sigma: float,
           rebinned: bool, units: str) -> FieldComparison:
    delta = o - r
    with np.errstate(invalid="ignore"):
        delta_err = np.sqrt(er**2 + eo**2)
        finite = np.isfinite(r) & np.isfinite(o) & np.isfinite(er) & np.isfinite(eo)
        # no error in either run and the same value (to round-off): an empty bin, or a
        # quantity known exactly (the mean mass of equal particles)
        empty = (er == 0) & (eo == 0) & np.isclose(r, o, rtol=1e-9, atol=0.0)
    use = finite & ~empty & dense
    z, _, p = z_test(delta[use], eo[use], er[use], dofs[1], dofs[0])
    n = int(use.sum())
    level = sidak_level(sigma, n)
    norm = float(np.sqrt(np.sum(r[use] ** 2)))
    l2, noise = float(np.sqrt(np.sum(delta[use] ** 2))), float(np.sqrt(np.sum(delta_err[use] ** 2)))
    with np.errstate(divide="ignore", invalid="ignore"):  # ‖ref‖ = 0: inf (or nan for 0/0)
        rel, floor, debiased = (float(np.float64(v) / norm) if n else math.nan for v in
                                (l2, noise, math.sqrt(max(0.0, l2**2 - noise**2))))
    ref_noise = float(np.sqrt(np.sum(er[use] ** 2)))
    p_min = float(p.min()) if n else 1.0
    return FieldComparison(
        name=name, y=y, reference=r, reference_err=er, other=o, other_err=eo, delta=delta,
        delta_err=delta_err, rel_l2=rel, rel_l2_floor=floor,
        max_z=float(np.max(np.abs(z))) if n else math.nan, resolved=bool(n and p_min < level),
        rebinned=rebinned, rel_l2_debiased=debiased, p=p_min, level=level, compared=use,
        reference_is_zero=bool(n) and norm <= 2.0 * ref_noise, units=units)


def _on_grid(res: Results, edges: np.ndarray | None, dim: int
             ) -> tuple[dict[str, np.ndarray], dict[str, np.ndarray] | None, list[str]]:
    """The run's profiles and stress group on ``edges`` (``None``: as stored), and what
    could not be put there."""
    prof, stress = res.profiles, _stress(res)
    left: list[str] = []
    if stress is not None and (stress["edges"].shape != prof["edges"].shape or
                               not np.allclose(stress["edges"], prof["edges"])):
        stress, left = None, ["stress (on other bins than the profiles)"]
    if edges is None:
        return prof, stress, left
    k = float(res.profile_attrs.get("inertia_factor", 0.5 if dim == 2 else 0.4))
    moved, rest = rebin_profiles(prof, edges, dim, k)
    if stress is not None:
        stress = rebin_stress(stress, prof, edges, dim)
    return moved, stress, left + [f"{name} (not rebinned)" for name in rest]


def _units(dataset: str, dim: int) -> str:
    from ..io.fields import field_info

    group = "stress" if dataset == "stress" else "profiles"
    return field_info(group, "total" if dataset == "stress" else dataset, dim)["units"]


def compare_pair(ref: Results, other: Results, fields: Sequence[str] | None = None,
                 sigma: float = 3.0, min_solid_fraction: float = 0.0) -> Comparison:
    """One run against the reference (:func:`compare`)."""
    labels = (_label(ref), _label(other))
    notes = [n for n in (_replica_note(ref, "reference"), _replica_note(other, "other")) if n]
    for lab, res in zip(labels, (ref, other), strict=True):
        if not res.profiles or "edges" not in res.profiles or "solid_fraction" not in \
                res.profiles:
            raise NotComparable(f"{lab}: no profiles to compare (run with the profiles "
                             "statistic, or demstudy analyze FILE --what profiles)")
    dims = [_dim(r) for r in (ref, other)]
    if dims[0] != dims[1]:
        raise NotComparable(f"different dimensions: {labels[0]} is {dims[0]}D, {labels[1]} is "
                         f"{dims[1]}D")
    axes = [r.profile_attrs.get("axis", "y") for r in (ref, other)]
    if axes[0] != axes[1]:
        raise NotComparable(f"profiles along different axes: {labels[0]} along {axes[0]}, "
                         f"{labels[1]} along {axes[1]}")
    dim = dims[0] or 3
    engines = [r.attrs.get("engine", "?") for r in (ref, other)]
    if engines[0] != engines[1]:
        notes.append(f"engines differ: {engines[0]} (reference) vs {engines[1]}")
    softs = [_soft(r) for r in (ref, other)]
    if softs[0] and softs[1] and softs[0] != softs[1]:
        notes.append(f"soft contacts differ: {softs[0]} (reference) vs {softs[1]}")
    e_ref, e_oth = ref.profiles["edges"], other.profiles["edges"]
    grid = common_grid(e_ref, e_oth)
    parts = [_on_grid(r, grid, dim) for r in (ref, other)]
    rebinned = grid is not None
    if rebinned:
        moved = [lab for lab, e in zip(labels, (e_ref, e_oth), strict=True)
                 if e.shape != grid.shape or not np.allclose(e, grid)]
        notes.append(f"rebinned: {len(e_ref) - 1} bins on [{e_ref[0]:g}, {e_ref[-1]:g}] "
                     f"(reference) and {len(e_oth) - 1} on [{e_oth[0]:g}, {e_oth[-1]:g}] "
                     f"compared on {len(grid) - 1} common bins on [{grid[0]:g}, "
                     f"{grid[-1]:g}]; moved: {', '.join(moved)} (temperatures and kinetic "
                     "stresses include the spread of the finer bins' mean velocities)")
        if any(splits_bins(e, grid) for e in (e_ref, e_oth)):
            notes.append("the grids do not nest: bins split between common bins are taken "
                         "as uniform inside")
    left = sorted(set(parts[0][2]) | set(parts[1][2]))
    if left:
        notes.append(f"not compared: {', '.join(left)}")
    split = [_split_fields(p, s) for p, s, _ in parts]
    names = _select(fields, split[0], split[1], labels, notes)
    y = parts[0][0]["y"] if "y" in parts[0][0] else \
        0.5 * (parts[0][0]["edges"][1:] + parts[0][0]["edges"][:-1])
    phi = [np.nan_to_num(np.asarray(p["solid_fraction"], float)) for p, _, _ in parts]
    dense = (phi[0] >= min_solid_fraction) & (phi[1] >= min_solid_fraction) \
        if min_solid_fraction > 0 else np.ones(len(y), bool)
    dofs = (block_dof(ref.profile_attrs), block_dof(other.profile_attrs))
    notes.append(f"degrees of freedom: reference {dof_note(ref.profile_attrs, dofs[0])}, "
                 f"other {dof_note(other.profile_attrs, dofs[1])}")
    out: dict[str, FieldComparison] = {}
    skipped: list[str] = []
    empty: list[str] = []
    exact: list[str] = []
    for name in names:
        r, er, dataset = split[0][name]
        o, eo, _ = split[1][name]
        if fields is None and _exact(r, er, o, eo):  # round-off errors: rows of noise
            exact.append(name)
            continue
        scalar = r.shape == (1,) and len(y) != 1
        fc = _field(name, np.array([np.nan]) if scalar else np.asarray(y, float), r, er, o, eo,
                    np.ones(1, bool) if scalar else dense, dofs, sigma, rebinned,
                    _units(dataset, dim))
        if fc.n_compared == 0 and fields is None:  # e.g. 3D stress xz: not measured
            empty.append(name)
            continue
        out[name] = fc
        if fc.n_compared < len(fc.y):
            skipped.append(f"{name} {len(fc.y) - fc.n_compared}")
    if empty:
        notes.append(f"no bin with a value and an error in both runs: {', '.join(empty)}")
    if exact:
        notes.append(f"exact in both runs: {', '.join(exact)}")
    if skipped:
        why = "empty in both, or without a finite value and error" + \
            (f", or below solid fraction {min_solid_fraction:g}" if min_solid_fraction else "")
        notes.append(f"bins left out ({why}): {', '.join(skipped)}")
    return Comparison(labels[0], labels[1], out, notes, sigma, rebinned)


Source = Results | str | os.PathLike


def compare(reference: Source | Sequence[Source], *others: Source | Sequence[Source],
            fields: Sequence[str] | None = None, sigma: float = 3.0,
            min_solid_fraction: float = 0.0) -> list[Comparison]:
    """Every other run against ``reference`` (results or files), one :class:`Comparison`
    each (see the module doc). Any argument may be a list of independent replicas of one
    run (other seeds): they are combined first (:func:`~.replicas.combine_replicas`: their
    mean, with the standard error across them), and the table's notes say so. ``fields``:
    labels (``temperature``, ``velocity[x]``, ``stress/xy``) or dataset names for all their
    components (``velocity``, ``stress``); default every field both runs hold. ``sigma``:
    the significance of each field's family test. ``min_solid_fraction``: leave out bins
    more dilute than this in either run.
    :class:`~demstudy.errors.NotComparable` (a ``ValueError``) naming the files for a missing
    file, runs of different dimension or profile axis, a file without profiles, bins that do
    not overlap or an unknown field."""
    if not others:
        raise NotComparable("compare needs a reference and at least one other run")
    if not (isinstance(sigma, int | float) and sigma > 0):
        raise NotComparable(f"sigma = {sigma!r}: must be > 0")
    ref = _load_group(reference)
    return [compare_pair(ref, _load_group(o), fields, sigma, min_solid_fraction)
            for o in others]
