"""Profiles ν, u_x, T, rotational T against y (or y/H) and the stress profiles P_xy, P_yy.

Dimensionless particle units: d = 1, m = 1, g = 1 with gravity. Stresses are compressive
positive, P = −σ (Campbell: τ_yy = P_yy, τ_xy = −P_xy), force per length in 2D, per area in 3D.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import numpy as np
from matplotlib.axes import Axes
from matplotlib.container import ErrorbarContainer
from matplotlib.figure import Figure
from matplotlib.ticker import MaxNLocator

from .common import MARKERS, Run, finish, new_figure, run_colour

PANELS = (
    ("solid_fraction", "solid fraction ν"),
    ("velocity", "mean velocity u_x (d/τ)"),
    ("temperature", "temperature T (m d²/τ², per d.o.f.)"),
    ("rotational_temperature", "rotational T (m d²/τ², per d.o.f.)"),
)


def _edges(prof: dict) -> np.ndarray:
    if "edges" in prof:
        return np.asarray(prof["edges"], float)
    y = np.asarray(prof["y"], float)
    h = float(y[1] - y[0]) if y.size > 1 else 1.0
    return np.append(y - 0.5 * h, y[-1] + 0.5 * h)


def reference_height(run: Run) -> tuple[float, float, str]:
    """(y_0, H, what H is) for y/H: the gap between the walls (channels, Couette cells; the
    mean servo gap over production), Campbell's flow depth 2 × mass-mean centre height above
    the base (open top), the periodic height (no walls) or, without a scene, the profile span."""
    from ..analysis.derived import campbell_depth

    prof, scene = run.results.profiles, run.scene
    edges = _edges(prof)
    if scene is None:
        return float(edges[0]), float(edges[-1] - edges[0]), "profile span"
    if scene.y_periodic or not scene.walls:
        return float(edges[0]), float(edges[-1] - edges[0]), "periodic height L_y"
    base = scene.wall_position("lower")
    if scene.has_open_top:
        return base, campbell_depth(prof, base), "flow depth (2 × mass-mean height)"
    ts = run.results.timeseries
    if "gap" in ts and "time" in ts:
        keep = ts["time"] >= float(run.attrs.get("equilibration_end", 0.0))
        keep = keep if np.any(keep) else np.ones_like(keep)
        lower = ts.get("wall_position_lower")
        base = float(np.mean(lower[keep])) if lower is not None else base
        return base, float(np.mean(ts["gap"][keep])), "gap between the walls (mean)"
    return base, scene.wall_position("upper") - base, "gap between the walls"


def set_height_label(ax: Axes, axis: str, scaled: bool, what: set[str], unit: str) -> None:
    """The profile axis's label: the axis in ``unit``, or (axis − axis_0)/H with what H is
    (``what``: the runs' kinds of H; several: see the legend)."""
    if scaled:
        kind = what.pop() if len(what) == 1 else "see the legend"
        ax.set_ylabel(f"({axis} − {axis}_0)/H,  H = {kind}")
    else:
        ax.set_ylabel(f"{axis} ({unit})")


def draw_profiles(runs: Sequence[Run], scaled: bool = False) -> Figure:
    """ν, u_x and T (translational and rotational) against y, one curve per results file;
    ``scaled``: against (y − y_0)/H (see :func:`reference_height`)."""
    fig, axes = new_figure(1, len(PANELS), height=4.5, sharey=True)
    axes = axes[0]
    what: set[str] = set()
    # (handle, label) of the strip and cell temperatures: their own legend in those panels
    cells: dict[Axes, list[tuple[ErrorbarContainer, str]]] = {ax: [] for ax in axes}
    for r, run in enumerate(runs):
        prof = run.results.profiles
        y = np.asarray(prof["y"], float)
        label = run.label
        if scaled:
            y0, height, kind = reference_height(run)
            y = (y - y0) / height
            what.add(kind)
            label += f", H = {height:.3g}"
        if "steady" in run.attrs and not run.attrs["steady"]:
            trend = 100 * run.attrs["kinetic_energy_trend"]
            label += f"\nNOT STEADY: kinetic energy changed {trend:+.0f} % over production"
        occupied = prof["solid_fraction"] > 1e-3
        n_cells = int(run.results.profile_attrs.get("z_cells", 1))
        prefix = f"{run.label}: " if len(runs) > 1 else ""
        for ax, (key, title) in zip(axes, PANELS, strict=True):
            if key not in prof:
                continue
            val, err = prof[key], prof.get(f"{key}_err")
            if val.ndim == 2:  # vectors: the flow (x) component
                val, err = val[:, 0], None if err is None else err[:, 0]
            mask = occupied if key != "solid_fraction" else np.ones_like(occupied)
            strip = ax.errorbar(val[mask], y[mask], xerr=None if err is None else err[mask],
                                marker="o", ms=3, capsize=2, label=label, color=f"C{r % 10}",
                                gid=f"{run.path.name}:{key}")
            if f"cell_{key}" in prof and n_cells > 1:
                # Malik's cells: fluctuations about each z-slab's mean, so a mean velocity
                # varying along z leaks less into T than in the strip
                cell_err = prof.get(f"cell_{key}_err")
                cell = ax.errorbar(prof[f"cell_{key}"][mask], y[mask], ls="--", marker="s",
                                   ms=2, capsize=2, mfc="none",
                                   xerr=None if cell_err is None else cell_err[mask],
                                   color=strip.lines[0].get_color(),
                                   label=f"{prefix}{n_cells} z-cells (Malik)",
                                   gid=f"{run.path.name}:cell_{key}")
                cells[ax].extend([(strip, f"{prefix}strip (Campbell)"),
                                  (cell, cell.get_label())])
            ax.set_xlabel(title)
            ax.grid(alpha=0.3)
    for ax in axes:  # few ticks, small values with a shared power of ten: labels apart
        ax.xaxis.set_major_locator(MaxNLocator(nbins=4))
        ax.ticklabel_format(axis="x", style="sci", scilimits=(-2, 4))
    set_height_label(axes[0], runs[0].results.profile_attrs.get("axis", "y"), scaled, what,
                     "particle diameters")
    for ax, pairs in cells.items():
        if pairs:
            ax.legend(*zip(*pairs, strict=True), fontsize=7, loc="upper right")
    # the runs' legend below the panels: profiles fill the panels' height, no corner is free
    return finish(fig, runs, "profiles: solid fraction, mean velocity, temperatures",
                  legend=axes[0].get_legend_handles_labels(), max_cols=2, legend_size=8)


def panels_with_legend_row(n_cols: int, legend_lines: int, width: float, height: float,
                           **kwargs: Any) -> tuple[Figure, np.ndarray, Axes]:
    """A Figure with one row of ``n_cols`` panels (``height`` inches) and below them an axes
    without frame spanning the width, for a legend of ``legend_lines`` lines (keeps the
    legend off the data and inside the tight layout)."""
    legend_height = 0.25 + 0.17 * legend_lines
    fig, grid = new_figure(2, n_cols, width=width, height=0.5 * (height + legend_height),
                           height_ratios=[height, legend_height], **kwargs)
    for ax in grid[1, 1:]:
        ax.remove()
    legend_row = grid[1, 0]
    legend_row.set_subplotspec(legend_row.get_subplotspec().get_gridspec()[1, :])
    legend_row.axis("off")
    return fig, grid[0], legend_row


CG_PANELS = (
    ("solid_fraction", "solid fraction ν"),
    ("velocity", "mean velocity u_x (d/τ)"),
    ("temperature", "temperature T (m d²/τ², per d.o.f.)"),
)


def _cg_reference_height(run: Run) -> tuple[float, float, str]:
    """(y_0, H, what H is) for the scaled coarse-grained profiles: the binned profiles' H
    (:func:`reference_height`), else the span of the evaluation points' cells."""
    if run.results.profiles and "y" in run.results.profiles:
        return reference_height(run)
    data, attrs = run.group("cgprofiles")
    y = np.asarray(data["y"], float)
    h = float(attrs.get("spacing", y[1] - y[0] if y.size > 1 else 1.0))
    return float(y[0] - 0.5 * h), float(y[-1] - y[0] + h), "span of the CG points"


def draw_cgprofiles(runs: Sequence[Run], scaled: bool = False) -> Figure:
    """Gaussian coarse-grained ν, u_x and T (MercuryCG kernel, ``/statistics/cgprofiles``)
    against the profile axis, lines with their error bands, over the binned profiles of the
    same file (``/profiles``, markers with error bars) so that the two can be compared: they
    agree where the fields vary slowly on the kernel width w; within 3 w of a wall the CG ν
    falls (the kernel mass beyond the wall is lost), and a velocity gradient u' adds
    u'² s²/dim to the CG temperature (s² = 0.973 w², attrs ``truncated_variance``) against
    u'² (h²/12 + the particle's own spread)/dim to a strip's (width h; the strips share each
    particle by its volume overlap). ``scaled``: against (y − y_0)/H
    (:func:`reference_height`)."""
    fig, axes, legend_row = panels_with_legend_row(len(CG_PANELS), len(runs), width=4.2,
                                                   height=4.6, sharey="row")
    what: set[str] = set()
    spans: list[float] = []  # where either profile holds particles (open tops: not above)
    for r, run in enumerate(runs):
        name, colour = run.path.name, f"C{r}"
        data, attrs = run.group("cgprofiles")
        prof = run.results.profiles if run.results.profiles and "y" in run.results.profiles \
            else {}
        y_cg = np.asarray(data["y"], float)
        y_bin = np.asarray(prof["y"], float) if prof else None
        if scaled:
            y0, height, kind = _cg_reference_height(run)
            what.add(kind)
            y_cg = (y_cg - y0) / height
            y_bin = None if y_bin is None else (y_bin - y0) / height
        prefix = f"{run.label}: " if len(runs) > 1 else ""
        if scaled:
            prefix = f"{run.label}, H = {height:.3g}: " if len(runs) > 1 else \
                f"H = {height:.3g}: "
        width = float(attrs.get("width", np.nan))
        # where the kernel sees particles (velocity is NaN beyond every particle's reach)
        cg_seen = np.asarray(data["solid_fraction"], float) > 1e-3
        occupied = np.asarray(prof["solid_fraction"], float) > 1e-3 if prof else None
        spans += list(y_cg[cg_seen]) + ([] if y_bin is None else list(y_bin[occupied]))
        for ax, (key, title) in zip(axes, CG_PANELS, strict=True):
            if prof and key in prof:
                val, err = np.asarray(prof[key], float), prof.get(f"{key}_err")
                err = None if err is None else np.asarray(err, float)
                if val.ndim == 2:  # vectors: the flow (x) component
                    val, err = val[:, 0], None if err is None else err[:, 0]
                mask = occupied if key != "solid_fraction" else np.ones_like(occupied)
                bin_width = float(run.results.profile_attrs.get(
                    "bin_width", np.diff(_edges(prof)).mean()))
                ax.errorbar(val[mask], y_bin[mask], xerr=None if err is None else err[mask],
                            ls="none", marker=MARKERS[r % len(MARKERS)], ms=4, mfc="none",
                            capsize=2, color=colour, zorder=3,
                            label=f"{prefix}binned (strips {bin_width:.3g} d wide)",
                            gid=f"{name}:{key}")
            if key not in data:
                continue
            val, err = np.asarray(data[key], float), data.get(f"{key}_err")
            err = np.zeros_like(val) if err is None else np.asarray(err, float)
            if val.ndim == 2:
                val, err = val[:, 0], err[:, 0]
            mask = (cg_seen if key != "solid_fraction" else np.ones_like(cg_seen)) \
                & np.isfinite(val)
            ax.plot(val[mask], y_cg[mask], color=colour, lw=1.5,
                    label=f"{prefix}coarse-grained, w = {width:.3g} d (± error band)",
                    gid=f"{name}:cg:{key}")
            ax.fill_betweenx(y_cg[mask], (val - err)[mask], (val + err)[mask], color=colour,
                             alpha=0.25, lw=0, gid=f"{name}:cg:{key}_err")
            ax.set_xlabel(title)
            ax.xaxis.set_major_locator(MaxNLocator(5))
            ax.grid(alpha=0.3)
    lo, hi = axes[0].get_ylim()
    if spans:  # empty space above an open top's flow is left out (1 d or 5 % margin)
        margin = 0.05 if scaled else 1.0
        axes[0].set_ylim(max(lo, min(spans) - margin), min(hi, max(spans) + margin))
    set_height_label(axes[0], runs[0].group("cgprofiles")[1].get("axis", "y"), scaled, what,
                     "d")
    handles, labels = axes[0].get_legend_handles_labels()
    legend_row.legend(handles, labels, fontsize=7, loc="center", ncol=2, frameon=False)
    taus = ", ".join(dict.fromkeys(str(run.attrs["time_unit"]) for run in runs
                                   if "time_unit" in run.attrs))
    return finish(fig, runs, "coarse-grained profiles (Gaussian kernel of width w, cut off at "
                             "3w; lines, bands: ± error) over the binned profiles (markers)"
                             + (f"\ntime unit {taus}" if taus else ""))


STRESS_PARTS = ("kinetic", "contact", "collisional", "total")
STRESS_STYLE = {"kinetic": ":", "contact": "--", "collisional": "--", "total": "-"}


def draw_stress(runs: Sequence[Run]) -> Figure:
    """Kinetic, contact / collisional and total P_xy and P_yy against y with error bars, the
    wall stresses (the column P_ay at each wall) as markers at the walls and, with gravity,
    Campbell's momentum-balance curves (P_xy = −τ_xy, P_yy = τ_yy) with their error band."""
    fig, axes = new_figure(1, 2, width=5.0, height=5.0, sharey=True)
    axes = axes[0]
    comps = (("xy", 0, 1), ("yy", 1, 1))
    for r, run in enumerate(runs):
        data, _attrs = run.group("stress")
        y = np.asarray(data["y"], float)
        edges = np.asarray(data.get("edges", _edges({"y": y})), float)
        prefix = f"{run.label}: " if len(runs) > 1 else ""
        for ax, (name, a, b) in zip(axes, comps, strict=True):
            for p, key in enumerate(STRESS_PARTS):
                if key not in data:
                    continue
                val = np.asarray(data[key], float)[:, a, b]
                err = data.get(f"{key}_err")
                err = None if err is None else np.asarray(err, float)[:, a, b]
                ax.errorbar(val, y, xerr=err, ls=STRESS_STYLE[key], marker=MARKERS[p], ms=3,
                            capsize=2, color=run_colour(r, p), label=f"{prefix}{key}",
                            gid=f"{run.path.name}:{key}:{name}")
            for side, y_wall in (("lower", edges[0]), ("upper", edges[-1])):
                if f"wall_{side}" not in data:
                    continue
                val = float(np.asarray(data[f"wall_{side}"], float)[a])
                err = data.get(f"wall_{side}_err")
                ax.errorbar([val], [y_wall], xerr=None if err is None else [float(err[a])],
                            marker="D" if side == "lower" else "v", ms=8, ls="none",
                            color=f"C{r % 10}", mfc="none", mew=1.5, capsize=3,
                            label=f"{prefix}{side} wall", gid=f"{run.path.name}:wall_{side}:{name}")
            key = f"balance_tau_{name}"
            if key in data:
                sign = -1.0 if name == "xy" else 1.0  # Campbell's tau_xy = -P_xy
                val = sign * np.asarray(data[key], float)
                err = np.asarray(data.get(f"{key}_err", np.zeros_like(val)), float)
                ax.plot(val, y, color="0.3", lw=1.5, gid=f"{run.path.name}:balance:{name}",
                        label=f"{prefix}momentum balance"
                              + (" (−τ_xy)" if name == "xy" else " (τ_yy)"))
                ax.fill_betweenx(y, val - err, val + err, color="0.3", alpha=0.15, lw=0)
            ax.axvline(0.0, color="0.7", lw=0.8)
            ax.set_xlabel(f"P_{name} (compressive positive, P = −σ)")
            ax.grid(alpha=0.3)
    axes[0].set_ylabel("y (particle diameters)")
    dims = {int(run.group("stress")[1].get("dim", 2)) for run in runs}
    per = "force per length (2D)" if dims == {2} else "force per area (3D)" if dims == {3} \
        else "force per length (2D) or area (3D)"
    # below the panels: the profiles span the whole height, no corner is free
    return finish(fig, runs, f"stress profiles in {per}; markers: wall stresses at the walls",
                  legend=axes[1].get_legend_handles_labels(), max_cols=3)


def draw_eos(runs: Sequence[Run]) -> Figure:
    """Campbell's equation of state χ(ν) = P_yy / (ρ_p Σ_a ⟨v_a'²⟩) per bin (the total P_yy of
    ``/stress`` and the profiles' velocity variances, :func:`demstudy.analysis.derived.
    equation_of_state`) against the bin's ν, with the kinetic-theory curve
    χ = ν Z(ν)/dim (Henderson's g0 for discs, Carnahan–Starling's for spheres, the scene's
    restitution e) and the elastic one."""
    from ..analysis.derived import equation_of_state
    from ..theory import campbell_chi

    fig, axes = new_figure(1, 1, width=5.5, height=4.5)
    ax = axes[0, 0]
    dims, nu_max = set(), 0.0
    for r, run in enumerate(runs):
        data, attrs = run.group("stress")
        prof = run.results.profiles
        dim = int(attrs.get("dim", 2))
        dims.add(dim)
        chi, err = equation_of_state(prof, np.asarray(data["total"], float)[:, 1, 1],
                                     np.asarray(data["total_err"], float)[:, 1, 1])
        nu = np.asarray(prof["solid_fraction"], float)
        ok = np.isfinite(chi) & (nu > 0.02)
        ax.errorbar(nu[ok], chi[ok], yerr=np.nan_to_num(err[ok]), ls="none",
                    marker=MARKERS[r % len(MARKERS)], ms=4, capsize=2, color=f"C{r}",
                    label=run.label, gid=f"{run.path.name}:chi")
        nu_max = max(nu_max, float(nu[ok].max()) if ok.any() else 0.0)
        e = float(run.scene.contact.restitution) if run.scene is not None else 1.0
        grid = np.linspace(0.01, min(0.99 * (0.9069 if dim == 2 else 0.7405),
                                     max(nu_max, 0.1) * 1.1), 200)
        ax.plot(grid, campbell_chi(grid, dim, e), color=f"C{r}", lw=1.2,
                label=f"kinetic theory, e = {e:g}", gid=f"{run.path.name}:chi_theory")
    ax.plot(grid, campbell_chi(grid, min(dims), 1.0), color="0.5", ls=":", lw=1.0,
            label="kinetic theory, e = 1")
    ax.set_xlabel("solid fraction ν")
    ax.set_ylabel("χ(ν) = P_yy / (ρ_p Σ⟨v'²⟩)")
    ax.set_yscale("log")
    ax.grid(alpha=0.3, which="both")
    g0 = "Henderson g0 (discs)" if dims == {2} else "Carnahan–Starling g0 (spheres)" \
        if dims == {3} else "Henderson / Carnahan–Starling g0"
    return finish(fig, runs, f"equation of state χ(ν), Campbell (1982); theory: {g0}",
                  legend=ax.get_legend_handles_labels(), max_cols=2)


def cooling_temperature(run: Run) -> tuple[np.ndarray, np.ndarray]:
    """(t − t_first, T) of a homogeneous cooling run from ``/timeseries``: T per translational
    degree of freedom, T = (2 E_kin − |P|²/M) / (dim (N − 1)) with M the total mass (the
    centre-of-mass motion is not thermal and takes dim degrees of freedom; without a momentum
    record T = 2 E_kin / (dim N))."""
    from ..scene.initial import particle_diameters

    ts, scene = run.results.timeseries, run.scene
    n, dim = scene.n_particles, scene.dimension
    energy = 2 * np.asarray(ts["kinetic_energy"], float)
    dof = dim * n
    if "momentum" in ts:
        # the run's diameters (the first draw of its seed), without building the start
        diameter = particle_diameters(scene, np.random.default_rng(scene.run.seed))
        total_mass = float((diameter**dim).sum())
        energy = energy - (np.asarray(ts["momentum"], float) ** 2).sum(axis=1) / total_mass
        dof = dim * (n - 1)
    t = np.asarray(ts["time"], float)
    return t - t[0], energy / dof


def draw_cooling(runs: Sequence[Run]) -> Figure:
    """Homogeneous cooling: T(t)/T0 on log–log axes (T0 the first sample's T) with Haff's law
    T/T0 = 1/(1 + t/t0)², t0 = 2 dim / ((1 − e²) ω_E(T0)), ω_E the Enskog collision
    frequency at the scene's ν (:func:`demstudy.theory.haff_temperature`; smooth particles)."""
    from ..theory import haff_t0, haff_temperature

    fig, axes = new_figure(1, 1, width=6.5, height=4.5)
    ax = axes[0, 0]
    for r, run in enumerate(runs):
        scene, name = run.scene, run.path.name
        t, temp = cooling_temperature(run)
        t0_temp = float(temp[0])
        keep = (t > 0) & (temp > 0)  # log axes: the origin t = 0 (T = T0) cannot be shown
        t, temp = t[keep], temp[keep]
        ax.plot(t, temp / t0_temp, marker=MARKERS[r % len(MARKERS)], ms=3, ls="none",
                color=f"C{r}", label=f"{run.label}: T/T0 (T0 = {t0_temp:.3g})",
                gid=f"{name}:temperature")
        nu, e, dim = scene.solid_fraction, scene.contact.restitution, scene.dimension
        t0 = haff_t0(nu, t0_temp, dim, e)
        label = f"Haff, ν = {nu:.3g}, e = {e:g}: t0 = {t0:.3g}"
        if scene.rotation_matters:  # rough particles also cool through their spins
            label += " (theory for smooth particles)"
        ax.plot(t, haff_temperature(t, nu, t0_temp, dim, e) / t0_temp, color=f"C{r}", ls="--",
                lw=1.2, label=label, gid=f"{name}:haff")
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlabel("t (particle units, from the first sample)")
    ax.set_ylabel("T(t) / T0 (per translational degree of freedom)")
    ax.grid(alpha=0.3, which="both")
    ax.legend(fontsize=7, loc="lower left")
    return finish(fig, runs, "homogeneous cooling and Haff's law T/T0 = 1/(1 + t/t0)²\n"
                             "t0 = 2 dim/((1 − e²) ω(T0)), ω the Enskog collision frequency")
