"""Independent replicas of one run (other seeds, same scene) combined into one ``Results``
whose errors come from the replicas' scatter (``ds.combine_replicas``).

Why: a run's own errors are block errors over its time series; they are honest only when
the blocks are longer than the slowest mode's correlation time. In some flows that time is
longer than the run (the bed's u_x(y) of the 2D rough-wall Couette cell at ν = 0.55 has
τ_int ≈ 1300 d/U_T against a 1200 d/U_T production: 16 replicas scatter 2.7× more than the
single-run errors say). Replicas of other seeds are independent, so the standard error of
their mean, std/√R, is honest whatever the correlation time; with R values it carries R − 1
degrees of freedom (``n_blocks = R``, so ``compare``'s Student-t test uses R − 1).

Dimensionless particle units: d = 1, m = 1, g = 1 when gravity acts (otherwise a wall speed
or the shear rate sets the time scale); every field keeps the units of its results file.
"""

from __future__ import annotations

import math
import os
import tomllib
import warnings
from collections.abc import Sequence

import numpy as np

from ..errors import NotComparable
from ..io.results import Results
from ..scene import flat_fields
from .core import _load, _stress

__all__ = ["combine_replicas", "is_combined"]

#: single-run error estimates that do not describe the replicas' errors: left out
SINGLE_RUN_ERROR_ATTRS = ("block_length", "error_block_length", "error_inefficiency",
                          "errors_converged", "effective_samples", "errors_unconverged_fields")


def is_combined(res: Results) -> bool:
    """Whether ``res`` is a replica mean made by :func:`combine_replicas`."""
    return res.profile_attrs.get("error_method") == "replicas"


def _name(res: Results, i: int) -> str:
    return res.path.name if res.path is not None else f"replica {i + 1}"


def _scene_without_seed(res: Results) -> dict | None:
    text = res.attrs.get("scene_toml")
    if not isinstance(text, str):
        return None
    scene = flat_fields(tomllib.loads(text))
    scene.pop("run.seed", None)
    return scene


def _check_same_run(runs: list[Results], names: list[str]) -> None:
    """Replicas differ in the seed only: same scene (``scene_toml`` without ``run.seed``),
    engine and engine options (edmd's t_c), same bins."""
    first = runs[0]
    scene = _scene_without_seed(first)
    for res, name in zip(runs[1:], names[1:], strict=True):
        other = _scene_without_seed(res)
        if other != scene:
            what = "one has no scene_toml" if other is None or scene is None else \
                ", ".join(f"{k} = {scene.get(k)!r} / {other.get(k)!r}"
                          for k in sorted(set(scene) | set(other))
                          if scene.get(k) != other.get(k))
            raise NotComparable(f"not replicas of one run: {names[0]} and {name} differ in "
                                f"their scenes apart from run.seed ({what})")
        for key in ("engine", "tc"):
            if first.attrs.get(key) != res.attrs.get(key):
                raise NotComparable(f"not replicas of one run: {key} = "
                                    f"{first.attrs.get(key)!r} in {names[0]}, "
                                    f"{res.attrs.get(key)!r} in {name}")
        for label, a, b in (("profile bins", first.profiles.get("edges"),
                             res.profiles.get("edges")),
                            ("stress bins", (_stress(first) or {}).get("edges"),
                             (_stress(res) or {}).get("edges"))):
            if (a is None) != (b is None) or (a is not None and (
                    np.shape(a) != np.shape(b) or not np.allclose(a, b))):
                raise NotComparable(f"not replicas of one run: {names[0]} and {name} have "
                                    f"different {label} (replicas are combined bin by bin)")


def _mean_and_error(values: list[np.ndarray], errors: list[np.ndarray]
                    ) -> tuple[np.ndarray, np.ndarray]:
    """Mean over the replicas and its standard error std/√n (n the replicas with a finite
    value in that bin; fewer than 2: NaN). Values known exactly in every replica (error 0)
    and equal to round-off (the mean mass of equal particles) keep the first value and error
    0, so that ``compare`` still recognises them as exact."""
    stack = np.stack([np.asarray(v, float) for v in values])
    quoted = np.stack([np.asarray(e, float) for e in errors])
    n = np.sum(np.isfinite(stack), axis=0)
    with np.errstate(invalid="ignore", divide="ignore"), warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)  # bins empty in every replica
        mean = np.nanmean(stack, axis=0)
        err = np.nanstd(stack, axis=0, ddof=1) / np.sqrt(n)
    err = np.where(n >= 2, err, np.nan)
    same = np.all(stack == stack[0], axis=0) | (
        np.all(quoted == 0, axis=0) & np.all(np.isclose(stack, stack[0], rtol=1e-9, atol=0),
                                             axis=0))
    return np.where(same, stack[0], mean), np.where(same, 0.0, err)


def _combine_group(groups: list[dict[str, np.ndarray]]) -> dict[str, np.ndarray]:
    """Every dataset with an ``_err`` partner: the replica mean and its standard error;
    other datasets (edges, y, counts): the first replica's when equal in all, else their
    mean."""
    first = groups[0]
    out: dict[str, np.ndarray] = {}
    for name, value in first.items():
        if name.endswith("_err") and name[:-4] in first:
            continue
        values = [g[name] for g in groups if name in g]
        if len(values) != len(groups) or any(np.shape(v) != np.shape(value) for v in values):
            continue  # not in every replica (or of another shape): not combined
        if f"{name}_err" in first:
            out[name], out[f"{name}_err"] = _mean_and_error(
                values, [g.get(f"{name}_err", np.nan) for g in groups])
        elif all(np.array_equal(v, value) for v in values) or \
                not np.issubdtype(np.asarray(value).dtype, np.number):
            out[name] = value
        else:
            out[name] = np.mean(np.stack([np.asarray(v, float) for v in values]), axis=0)
    return out


def _scatter_ratio(runs: list[Results], combined: dict[str, np.ndarray]) -> float:
    """Median over fields of the replicas' scatter against their own quoted errors:
    √(Σ std²/Σ σ_quoted²) per field, std = √R × the combined error (1: the single-run errors
    were honest; above 1: too small, e.g. a correlation time longer than the blocks)."""
    ratios = []
    r = len(runs)
    for name, value in combined.items():
        if not name.endswith("_err") or name[:-4] not in combined:
            continue
        std2 = (np.asarray(value, float) * math.sqrt(r)) ** 2
        quoted2 = np.mean(np.stack([np.asarray(res.profiles[name], float) ** 2
                                    for res in runs]), axis=0)
        use = np.isfinite(std2) & np.isfinite(quoted2) & (quoted2 > 0)
        if np.any(use):
            ratios.append(math.sqrt(float(np.sum(std2[use]) / np.sum(quoted2[use]))))
    return float(np.median(ratios)) if ratios else math.nan


def combine_replicas(runs: Sequence[Results | str | os.PathLike]) -> Results:
    """One ``Results`` from R ≥ 2 independent replicas of one run (other seeds): profiles
    (and the stress group, when present) are the replicas' mean, their ``*_err`` the standard
    error across replicas, std/√R (ddof = 1; per component for vectors and tensors; bins
    empty in some replicas use those that hold a value). ``profile_attrs`` say
    ``replicas = R``, ``error_method = "replicas"``, ``n_blocks = R`` (R − 1 degrees of
    freedom in ``compare``) and ``scatter_to_quoted_error`` (the median over fields of the
    replicas' scatter against their own quoted errors); timeseries are the first replica's;
    ``attrs`` the first's with ``wall_seconds`` summed, ``replicas``, ``replica_seeds`` and
    ``replica_files``. Other groups (health, statistics) are not combined.

    Refuses (:class:`~demstudy.errors.NotComparable`, naming the files) fewer than two runs,
    runs of different scenes apart from ``run.seed``, engines or t_c, and different bins."""
    runs = list(runs)
    if len(runs) < 2:
        raise NotComparable(f"combine_replicas needs at least 2 replicas, got {len(runs)} "
                            "(one run keeps its own block errors)")
    loaded = [_load(r) for r in runs]
    names = [_name(res, i) for i, res in enumerate(loaded)]
    for res, name in zip(loaded, names, strict=True):
        if not res.profiles or "edges" not in res.profiles:
            raise NotComparable(f"{name}: no profiles to combine")
        if is_combined(res):
            raise NotComparable(f"{name} is already a replica mean: combine the replicas "
                                "themselves")
    _check_same_run(loaded, names)
    r = len(loaded)
    first = loaded[0]
    profiles = _combine_group([res.profiles for res in loaded])
    groups, group_attrs = {}, {}
    stress = [_stress(res) for res in loaded]
    if all(s is not None for s in stress):
        key = next(k for k in ("stress", "statistics/stress") if first.groups.get(k) is
                   stress[0])
        groups[key] = _combine_group(stress)
        group_attrs[key] = dict(first.group_attrs.get(key, {}))
    profile_attrs = {k: v for k, v in first.profile_attrs.items()
                     if k not in SINGLE_RUN_ERROR_ATTRS}
    profile_attrs.update(replicas=r, error_method="replicas", n_blocks=r,
                         samples=sum(int(res.profile_attrs.get("samples", 0)) for res in loaded),
                         scatter_to_quoted_error=_scatter_ratio(loaded, profiles))
    attrs = dict(first.attrs)
    walls = [res.attrs.get("wall_seconds") for res in loaded]
    if all(w is not None for w in walls):
        attrs["wall_seconds"] = float(sum(walls))
    seeds = [res.attrs.get("seed") for res in loaded]
    if all(s is not None for s in seeds) and len(set(seeds)) < r:
        raise NotComparable(f"not independent replicas: seeds {seeds} of {', '.join(names)} "
                            "repeat")
    attrs.update(replicas=r, replica_files=",".join(names),
                 replica_seeds=",".join(str(s) for s in seeds))
    return Results(attrs, timeseries=dict(first.timeseries), profiles=profiles,
                   profile_attrs=profile_attrs, groups=groups, group_attrs=group_attrs)
