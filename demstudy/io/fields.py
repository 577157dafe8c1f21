"""Units and one-line descriptions of every dataset of a results file.

The writer (:func:`demstudy.io.results.write_results`) gives each dataset the attributes
``units`` and ``description`` from :func:`field_info`. Units are dimensionless particle
units: d (diameter, length), m (particle mass) and τ, the scene's time unit, stated in the
root attribute ``time_unit`` (:func:`time_unit`): τ = √(d/g) with gravity, otherwise set by a
moving wall's speed (d/U), the shear rate (1/γ̇, strain units) or the initial temperature
(d √(m/T₀)). Quantities of 2D runs are per unit thickness (discs), so a "stress" is a force per
length in 2D and a force per area in 3D.

Lookup rules (:func:`field_info`): the group's table (``stress`` also serves
``statistics/stress``); ``<name>_err`` is "standard error of <description of name>" in the
units of ``name``; in ``statistics/waves`` a plane suffix ``_xy``, ``_xz``, ``_yz`` is taken off
and named; anything else gets the units ``"see docs/results-format.md"`` and a description
naming the group, so no dataset is ever without both attributes.
"""

from __future__ import annotations

import math
import re
import tomllib
from collections.abc import Mapping
from typing import Any

__all__ = ["FIELDS", "UNKNOWN_UNITS", "field_info", "time_unit"]

UNKNOWN_UNITS = "see docs/results-format.md"

# -- units (τ: the scene's time unit, see time_unit) ------------------------------------
ONE = "1"
COUNT = "1 (count)"
LENGTH = "d"
TIME = "τ"
SPEED = "d/τ"
RATE = "1/τ"
SPIN = "1/τ (rad/τ)"
MASS = "m"
MOMENTUM = "m d/τ"
FORCE = "m d/τ^2"
ENERGY = "m d^2/τ^2"
SPEED2 = "d^2/τ^2"
ANGLE = "rad"
PER_ANGLE = "1/rad"
PER_LENGTH = "1/d"
PER_TIME = "1/τ"
WAVENUMBER = "1 (integer: periods per box length)"
INDEX = "1 (index)"

# dimension-dependent units, {name} placeholders in the tables
BY_DIM: dict[str, dict[int | None, str]] = {
    "stress": {2: "m/τ^2 (force per length)", 3: "m/(d τ^2) (force per area)",
               None: "m d^(2-dim)/τ^2 (force per length in 2D, per area in 3D)"},
    "number_density": {2: "1/d^2", 3: "1/d^3", None: "1/d^dim"},
    "mass_density": {2: "m/d^2", 3: "m/d^3", None: "m/d^dim"},
    "momentum_density": {2: "m/(d τ)", 3: "m/(d^2 τ)", None: "m/(d^(dim-1) τ)"},
    "force_density": {2: "m/(d τ^2)", 3: "m/(d^2 τ^2)", None: "m/(d^(dim-1) τ^2)"},
    "volume": {2: "d^2", 3: "d^3", None: "d^dim"},
}

_BINS = {
    "y": (LENGTH, "bin centres along the profile axis"),
    "edges": (LENGTH, "bin edges along the profile axis"),
}

_PROFILES = {
    **_BINS,
    "solid_fraction": (ONE, "volume (2D: area) fraction of the bin, exact disc/sphere overlap"),
    "number_density": ("{number_density}", "particles per unit volume (2D: area)"),
    "mean_mass": (MASS, "mass per particle in the bin"),
    "velocity": (SPEED, "mass-weighted mean velocity (x, y[, z])"),
    "temperature": (ENERGY, "translational temperature per degree of freedom, m<v'^2>/dim"),
    "temperature_components": (ENERGY, "m<u'^2>, m<v'^2>[, m<w'^2>] about the bin's mean"),
    "kinetic_shear": (SPEED2, "<u'v'>: velocity fluctuation covariance (x, y)"),
    "spin": (SPIN, "mass-weighted mean angular velocity (z in 2D; x, y, z in 3D)"),
    "rotational_temperature": (ENERGY, "I<ω'^2> per rotational degree of freedom"),
    "mean_temperature": (ENERGY, "the mass-weighted mean over the bins of the translational "
                                 "temperature (one number for the run)"),
    "cell_temperature": (ENERGY, "temperature with fluctuations about Malik's z-cell means"),
    "cell_temperature_components": (ENERGY, "temperature components about the z-cell means"),
    "cell_rotational_temperature": (ENERGY, "rotational temperature about the z-cell means"),
}

_TIMESERIES = {
    "time": (TIME, "simulation time of the sample"),
    "momentum": (MOMENTUM, "total momentum Σ m v of the mobile particles"),
    "kinetic_energy": (ENERGY, "translational kinetic energy ½ Σ m v² (total: the mean "
                               "flow included)"),
    "peculiar_kinetic_energy": (ENERGY, "y-periodic boxes: ½ Σ m v'², v' the velocity about "
                                        "the mean flow (Lees–Edwards streaming profile "
                                        "γ̇ y x̂ and the mean drift removed)"),
    "temperature": (ENERGY, "y-periodic boxes: granular temperature Σ m v'²/(dim N) per "
                            "translational degree of freedom, v' as in "
                            "peculiar_kinetic_energy"),
    "rotational_energy": (ENERGY, "rotational kinetic energy ½ Σ I ω² (total)"),
    "wall_force_lower": (FORCE, "force of the particles on the lower wall, mean over the "
                                "interval ending at the sample (NaN at t = 0)"),
    "wall_force_upper": (FORCE, "force of the particles on the upper wall, mean over the "
                                "interval ending at the sample (NaN at t = 0)"),
    "wall_work_lower": (ENERGY, "work done by the lower wall on the particles since t = 0"),
    "wall_work_upper": (ENERGY, "work done by the upper wall on the particles since t = 0"),
    "tilt": (LENGTH, "Lees–Edwards x offset of the upper periodic image, in [−L_x/2, L_x/2]"),
    "gap": (LENGTH, "servo: gap between the walls"),
    "width": (LENGTH, "servo: periodic width (x period) of the box"),
    "wall_position_lower": (LENGTH, "servo: y of the lower wall plane"),
    "wall_position_upper": (LENGTH, "servo: y of the upper wall plane"),
    "wall_velocity_upper": (SPEED, "servo: x speed of the upper wall"),
    "collisions": (COUNT, "pair collisions since t = 0 (event-driven)"),
    "wall_collisions": (COUNT, "wall and bump collisions since t = 0 (event-driven)"),
    "elastic_tc_collisions": (COUNT, "pair collisions the TC model made elastic since t = 0 "
                                     "(event-driven)"),
    "dissipated_energy": (ENERGY, "energy dissipated in collisions since t = 0 "
                                  "(event-driven; translational + rotational)"),
    "gravity_work": (ENERGY, "work done by gravity on the particles since t = 0"),
    "pressure": ("{stress}", "y-periodic boxes: pressure, peculiar kinetic part "
                             "2 E'_kin/(dim V) at the sample + the interaction part: "
                             "event-driven, collisional over the interval ending at the "
                             "sample (NaN at t = 0); soft, the contact virial at the "
                             "sample"),
}

_FRAMES = {
    "time": (TIME, "time of the frame"),
    "position": (LENGTH, "particle centres"),
    "velocity": (SPEED, "particle velocities"),
    "angular_velocity": (SPIN, "particle angular velocities (z in 2D; x, y, z in 3D)"),
    "radius": (LENGTH, "particle radii"),
    "box_lo": (LENGTH, "lower box corner"),
    "box_hi": (LENGTH, "upper box corner"),
    "tilt": (LENGTH, "Lees–Edwards x offset of the upper periodic image"),
    "walls": (LENGTH, "walls that move (servo): y of the lower and upper wall planes at the "
                      "frame"),
}

_STRESS = {
    **_BINS,
    "kinetic": ("{stress}", "kinetic stress tensor ρν<v'v'> per bin, compressive positive"),
    "contact": ("{stress}", "contact stress tensor of the soft contacts per bin, "
                            "compressive positive"),
    "collisional": ("{stress}", "collisional stress tensor of the hard collisions per bin, "
                                "compressive positive"),
    "total": ("{stress}", "total stress tensor (kinetic + contact or collisional), "
                          "compressive positive"),
    "wall_lower": ("{stress}", "column P_ay at the lower wall, from its force over production"),
    "wall_upper": ("{stress}", "column P_ay at the upper wall, from its force over production"),
    "balance_tau_xy": ("{stress}", "Campbell's τ_xy from the momentum balance"),
    "balance_tau_yy": ("{stress}", "Campbell's τ_yy from the momentum balance"),
    "balance_inertia": ("{force_density}", "ρνa per bin from the momentum change over "
                                           "production (Campbell's unsteady term)"),
}

_COLLISIONS = {
    "time": (TIME, "time of the collision"),
    "kind": ("1 (code: 0 pair, 1 lower wall, 2 upper wall)", "kind of collision"),
    "i": (INDEX, "input index of particle i"),
    "j": (INDEX, "input index of particle j (−1 flat wall; ≥ N a bump)"),
    "position": (LENGTH, "contact point"),
    "normal": (ONE, "unit normal from i to j (or to the wall)"),
    "branch": (LENGTH, "r_j − r_i at contact (walls: contact point − r_i)"),
    "impulse": (MOMENTUM, "impulse received by i"),
    "velocity": (SPEED, "pre-collision v_i − v_j of the centres (walls: minus the wall's)"),
    "spin_velocity": (SPEED, "pre-collision relative velocity of the contact points"),
}

_VDF = {
    **_BINS,
    "count": (ONE, "particle centres in the bin per frame"),
    "mean": ("d/τ (u, v, w, √j ω), 1/τ (ω)", "run mean of each component per bin "
                                              "(attribute components)"),
    "variance": ("d^2/τ^2 (u, v, w, √j ω), 1/τ^2 (ω)", "variance of each component per bin "
                                                        "(attribute components)"),
    "skewness": (ONE, "skewness <c'^3>/<c'^2>^(3/2) of each component per bin"),
    "kurtosis": (ONE, "kurtosis <c'^4>/<c'^2>^2 of each component per bin"),
    "X": (ONE, "Campbell's X1…X5 histograms per bin, density per unit X"),
    "X_edges": (ONE, "X histogram bin edges"),
    "X_centres": (ONE, "X histogram bin centres"),
    "X_reference": (ONE, "folded Maxwellian (chi) reference averaged over each X bin"),
    "X_reference_centre": (ONE, "folded Maxwellian (chi) reference at the X bin centres"),
    "malik_pdf": (ONE, "Malik's histogram of x = (c − M)/√S per bin and component, density "
                       "per unit x"),
    "malik_P": (ONE, "Malik's histogram scaled to P(0) = 1"),
    "malik_edges": (ONE, "Malik histogram bin edges in x"),
    "malik_centres": (ONE, "Malik histogram bin centres in x"),
    "gaussian": (ONE, "exp(−x²/2) at the Malik bin centres"),
    "gaussian_binned": (ONE, "normal density averaged over each Malik bin, scaled to P(0) = 1"),
}

_GR = {
    **_BINS,
    "edges_y": (LENGTH, "y-bin edges"),
    "r": (LENGTH, "shell centres"),
    "r_edges": (LENGTH, "shell edges"),
    "g": (ONE, "pair correlation g(r) per y-bin"),
    "pairs_per_particle": (ONE, "partners per particle in each shell"),
    "mean_count": (ONE, "particles per frame in the y-bin"),
    "shell_volume": ("{volume}", "slab-weighted shell volume"),
    "image_artefact": (ONE, "true for shells beyond half the shortest periodic length"),
}

_STRUCTURE = {
    "r": (LENGTH, "slice centres (|Δy| for normal, in-plane distance for parallel)"),
    "normal": ("{number_density}", "Campbell's pair distribution normal to the flow "
                                   "(vs |Δy|) around mid-plane test particles"),
    "parallel": ("{number_density}", "Campbell's pair distribution in the flow plane "
                                     "around mid-plane test particles"),
}

_ANGLES = {
    **_BINS,
    "theta_edges": (ANGLE, "collision-angle bin edges"),
    "theta": (ANGLE, "collision-angle bin centres"),
    "p_text": (PER_ANGLE, "P(θ) per y-bin, θ from the flow direction (thesis text)"),
    "p_listing": (PER_ANGLE, "P(θ) per y-bin, θ as in Campbell's listing"),
    "pair_collisions": (COUNT, "pair collisions used per y-bin"),
    "wall_collisions": (COUNT, "wall collisions per y-bin"),
    "s_text": (ONE, "Savage–Jeffrey S = 2R du/dy/√<u'^2> (text)"),
    "s_listing": (ONE, "Savage–Jeffrey S = 2R |du/dy|/√(<u'^2>+<v'^2>) (listing)"),
    "sj_text_R": (PER_ANGLE, "Savage–Jeffrey P(θ), text S, length R"),
    "sj_text_C": (PER_ANGLE, "Savage–Jeffrey P(θ), text S, mean spacing C"),
    "sj_listing_R": (PER_ANGLE, "Savage–Jeffrey P(θ), listing S, length R"),
    "sj_listing_C": (PER_ANGLE, "Savage–Jeffrey P(θ), listing S, length C/2"),
}

_FREEPATH = {
    **_BINS,
    "lambda_edges": (LENGTH, "free-path histogram bin edges"),
    "lambda": (LENGTH, "free-path histogram bin centres"),
    "tau_edges": (TIME, "free-time histogram bin edges"),
    "tau": (TIME, "free-time histogram bin centres"),
    "p_lambda": (PER_LENGTH, "P(λ) per y-bin, per unit length"),
    "p_tau": (PER_TIME, "P(τ) per y-bin, per unit time"),
    "mean_free_path": (LENGTH, "mean free path <λ> per y-bin, relative to the local mean "
                               "flow"),
    "mean_free_time": (TIME, "mean free time <τ> per y-bin"),
    "lambda_ratio": (ONE, "<λ²>/<λ>² per y-bin"),
    "tau_ratio": (ONE, "<τ²>/<τ>² per y-bin"),
    "knudsen": (ONE, "Kn = <λ>/W per y-bin (W: attribute knudsen_width)"),
    "lab_mean_free_path": (LENGTH, "<λ> per y-bin from the lab-frame displacement (mean "
                                   "flow included)"),
    "lab_knudsen": (ONE, "lab-frame Kn = lab_mean_free_path/W per y-bin"),
    "all_lab_mean_free_path": (LENGTH, "lab-frame <λ> pooled over the bins"),
    "collision_rate": (RATE, "particle collisions per unit time with the centre in the bin"),
    "collision_frequency": (RATE, "collisions per particle per unit time"),
    "all_mean_free_path": (LENGTH, "<λ> pooled over the bins"),
    "all_mean_free_time": (TIME, "<τ> pooled over the bins"),
    "all_lambda_ratio": (ONE, "<λ²>/<λ>² pooled over the bins"),
    "all_tau_ratio": (ONE, "<τ²>/<τ>² pooled over the bins"),
    "lambda_enskog": (LENGTH, "Enskog mean free path of the bin's solid fraction"),
    "tau_enskog": (TIME, "Enskog mean free time of the bin's ν and T"),
    "knudsen_enskog": (ONE, "Enskog Knudsen number λ_Enskog/W"),
    "flights": (COUNT, "flights counted per y-bin"),
    "collisions": (COUNT, "particle collisions per y-bin"),
}

_VCORR = {
    **_BINS,
    "r_edges": (LENGTH, "shell edges"),
    "r": (LENGTH, "shell centres"),
    "C": (ONE, "normalised velocity correlation C_αα(r) per y-bin"),
    "covariance": (SPEED2, "<u'_iα u'_jα> over the pairs of each shell"),
    "C_offdiag": (ONE, "symmetrised off-diagonal correlation C_αβ(r) (attribute "
                       "offdiag_components)"),
    "covariance_offdiag": (SPEED2, "symmetrised off-diagonal covariance"),
    "C_offdiag_antisym": (ONE, "antisymmetric part of the off-diagonal correlation"),
    "temperature_components": (SPEED2, "<u'_α²> per y-bin"),
    "C_malik": (PER_LENGTH, "Malik's eq. 4.1 correlation, δ binned as 1/dr"),
    "pairs_per_particle": (ONE, "ordered partners per particle in each shell"),
    "count": (ONE, "particles per frame in the y-bin"),
    "image_artefact": (ONE, "true for shells beyond half the shortest periodic length"),
}

_LAMBDA = {
    **_BINS,
    "lambda": (ONE, "Malik's Λ = <cos² Ψ>, time average of per-frame bin averages"),
    "lambda_pooled": (ONE, "Σ cos² Ψ / Σ N over all frames"),
    "count": (ONE, "particles used per frame"),
}

_WAVES = {  # names without the plane suffix
    "field": (ONE, "mean solid-fraction field"),
    "spectrum": (ONE, "mean power spectrum of the solid-fraction field (numpy FFT order)"),
    "k_x": (WAVENUMBER, "wavenumbers along x"),
    "k_y": (WAVENUMBER, "wavenumbers along y"),
    "k_z": (WAVENUMBER, "wavenumbers along z"),
    "family_power": (ONE, "power per family (|k_a|, |k_b|)"),
    "amplitude": (ONE, "amplitude √P of each family"),
    "antisymmetric_fraction": (ONE, "share of a family's power antisymmetric about the "
                                    "centreline"),
    "dominant": (WAVENUMBER, "(k_a, k_b) of the dominant families, strongest first"),
    "leading": (WAVENUMBER, "(k_a, k_b) of the five strongest families"),
    "leading_amplitude": (ONE, "amplitudes of the five strongest families"),
    "series": (ONE, "per-frame amplitudes of the families with |k| ≤ 3, pairwise averaged"),
    "series_modes": (WAVENUMBER, "(k_a, k_b) of the series columns"),
    "series_time": (TIME, "times of the series points"),
    "series_frames": (COUNT, "frames averaged into each series point"),
}

_CGPROFILES = {
    "y": (LENGTH, "evaluation points along the profile axis"),
    "number_density": ("{number_density}", "coarse-grained number density Σφ/A"),
    "solid_fraction": (ONE, "coarse-grained solid fraction ΣVφ/A"),
    "density": ("{mass_density}", "coarse-grained mass density ν/V_1"),
    "momentum_density": ("{momentum_density}", "coarse-grained momentum density"),
    "velocity": (SPEED, "coarse-grained velocity p/ρ"),
    "kinetic_stress": ("{stress}", "coarse-grained kinetic stress tensor"),
    "temperature": (ENERGY, "tr σ^k/(dim n)"),
}

_DERIVED = {
    **_BINS,
    "shear_rate": (RATE, "du/dy from a cubic spline through the finite bins"),
    "S_text": (ONE, "Savage–Jeffrey S = 2R du/dy/√<u'^2> (thesis text)"),
    "S_listing": (ONE, "S = 2R |du/dy|/√(<u'^2>+<v'^2>) (Campbell's listing)"),
    "tau_xy": ("{stress}", "Campbell's τ_xy = −P_xy of the measured total stress"),
    "tau_yy": ("{stress}", "Campbell's τ_yy = P_yy of the measured total stress"),
    "pressure": ("{stress}", "mean normal stress tr(P_total)/dim"),
    "f_s": (ONE, "Bagnold shear coefficient τ_xy/(ρ R² (du/dy)²) of the measured stress"),
    "f_N": (ONE, "Bagnold normal coefficient τ_yy/(ρ R² (du/dy)²) of the measured stress"),
    "friction": (ONE, "friction coefficient μ = τ_xy/τ_yy of the measured stress"),
    "balance_tau_xy": ("{stress}", "Campbell's τ_xy from the momentum balance"),
    "balance_tau_yy": ("{stress}", "Campbell's τ_yy from the momentum balance"),
    "f_s_balance": (ONE, "Bagnold shear coefficient of the momentum-balance τ_xy"),
    "f_N_balance": (ONE, "Bagnold normal coefficient of the momentum-balance τ_yy"),
    "friction_balance": (ONE, "μ = τ_xy/τ_yy of the momentum-balance stresses"),
    "chi": (ONE, "Campbell's χ = p/(ρ Σ_a<v_a'^2>) with p = tr(P_total)/dim"),
    "chi_balance": (ONE, "Campbell's χ with p = τ_yy of the momentum balance (chute)"),
    "chi_theory": (ONE, "kinetic theory χ = νZ/dim at the bin's ν (constant e)"),
    "slip_lower": (SPEED, "slip velocity u − U_wall at the lower wall plane"),
    "slip_upper": (SPEED, "slip velocity u − U_wall at the upper wall plane"),
    "knudsen_enskog": (ONE, "Kn = λ_Enskog(ν)/W (W: attribute knudsen_width)"),
    "lambda_enskog": (LENGTH, "Enskog mean free path of the bin's solid fraction"),
}

_HEALTH = {  # soft-contact engines, one value per production sample (demstudy.contact.health)
    "time": (TIME, "simulation time of the sample"),
    "max_overlap": (LENGTH, "largest overlap of the contacts touching at the sample "
                            "(particle–particle, particle–wall, particle–bump)"),
    "mean_overlap": (LENGTH, "mean overlap of the contacts touching at the sample (NaN: none)"),
    "contacts": (COUNT, "contacts touching at the sample (pairs, walls and bumps)"),
    "pair_contacts": (COUNT, "particle–particle contacts touching at the sample"),
    "wall_contacts": (COUNT, "particle–wall and particle–bump contacts touching at the sample"),
    "coordination": (ONE, "mean number of contacts per mobile particle"),
    "multi_contact_fraction": (ONE, "fraction of mobile particles in two or more contacts"),
    "persistent_fraction": (ONE, "share of the touching pairs already touching at the "
                                 "previous sample (NaN: unknown)"),
    "min_impact_speed": (SPEED, "smallest normal impact speed reconstructed from the "
                                "touching pairs (overlap and normal speed, elastic energy)"),
    "median_impact_speed": (SPEED, "median reconstructed normal impact speed of the pairs"),
    "max_impact_speed": (SPEED, "largest reconstructed normal impact speed of the pairs"),
}

_TRACKS = {
    "mark": (COUNT, "marked-grain numbers (the scene's marker numbers, ascending)"),
    "time": (TIME, "sample times (every sample from t = 0)"),
    "position": (LENGTH, "marked grains' centres (samples, markers, dim), x unwrapped across "
                         "the periodic boundary (continuous paths); NaN: absent"),
    "velocity": (SPEED, "marked grains' velocities (samples, markers, dim); NaN: absent"),
}

FIELDS: dict[str, dict[str, tuple[str, str]]] = {
    "tracks": _TRACKS,
    "timeseries": _TIMESERIES,
    "profiles": _PROFILES,
    "frames": _FRAMES,
    "stress": _STRESS,
    "collisions": _COLLISIONS,
    "health": _HEALTH,
    "statistics/vdf": _VDF,
    "statistics/gr": _GR,
    "statistics/structure": _STRUCTURE,
    "statistics/angles": _ANGLES,
    "statistics/freepath": _FREEPATH,
    "statistics/stress": _STRESS,
    "statistics/vcorr": _VCORR,
    "statistics/lambda": _LAMBDA,
    "statistics/waves": _WAVES,
    "statistics/cgprofiles": _CGPROFILES,
    "statistics/derived": _DERIVED,
}
"""group -> dataset name -> (units, description); ``{stress}`` etc. depend on the dimension
(:data:`BY_DIM`)."""

_PLANE = re.compile(r"^(?P<base>.+)_(?P<plane>xy|xz|yz)$")


def _units(template: str, dim: int | None) -> str:
    key = dim if dim in (2, 3) else None
    for name, table in BY_DIM.items():
        template = template.replace("{" + name + "}", table[key])
    return template


def _lookup(group: str, name: str) -> tuple[str, str] | None:
    table = FIELDS.get(group)
    if table is None:
        return None
    if name in table:
        return table[name]
    if group == "statistics/waves":
        match = _PLANE.match(name)
        if match and match["base"] in table:
            units, text = table[match["base"]]
            return units, f"{text}, plane {match['plane']}"
    return None


def field_info(group: str, name: str, dim: int | None = None) -> dict[str, str]:
    """``{"units": …, "description": …}`` of dataset ``name`` in ``group`` (e.g.
    ``"timeseries"``, ``"statistics/vdf"``, with or without a leading slash); ``dim`` makes
    dimension-dependent units explicit. Never empty (see the module doc)."""
    group = group.strip("/")
    found = _lookup(group, name)
    if found is None and name.endswith("_err"):
        base = name.removesuffix("_err")
        inner = _lookup(group, base)
        if inner is not None:
            found = inner[0], f"standard error of {inner[1]}"
        else:
            found = UNKNOWN_UNITS, f"standard error of '{base}' in /{group}"
    if found is None:
        found = UNKNOWN_UNITS, f"'{name}' in /{group} (see docs/results-format.md)"
    units, text = found
    return {"units": _units(units, dim), "description": text}


# -- the time unit ---------------------------------------------------------------------
def _number(value: float) -> str:
    return f"{value:.6g}"


def time_unit(scene: Any) -> str:
    """What τ, the time unit of a scene's numbers, is: a validated ``Scene``, the scene's
    data (a mapping, as read from TOML) or its TOML text.

    Gravity fixes τ = √(d/g); otherwise the fastest moving wall (τ = d/U), the shear rate
    (τ = 1/γ̇) or the initial temperature (τ = d √(m/T₀)), in that order; the magnitude is
    given so that a value other than 1 reads correctly."""
    if isinstance(scene, str):
        data: Mapping[str, Any] = tomllib.loads(scene)
    elif isinstance(scene, Mapping):
        data = scene
    else:
        data = scene.model_dump(mode="json")
    gravity = data.get("gravity")
    if gravity:
        g = float(gravity.get("magnitude", 1.0))
        if math.isclose(g, 1.0):
            return "τ = √(d/g): gravity g = 1 d/τ²"
        return f"τ set by gravity g = {_number(g)} d/τ² (√(d/g) = {_number(g ** -0.5)} τ)"
    moving = [(abs(float(w.get("velocity", 0.0))), w.get("side", "?"))
              for w in data.get("walls") or [] if float(w.get("velocity", 0.0)) != 0.0]
    if moving:
        speed, side = max(moving)
        if math.isclose(speed, 1.0):
            return f"τ = d/U: the {side} wall moves at U = 1 d/τ"
        return (f"τ set by the {side} wall's speed U = {_number(speed)} d/τ "
                f"(d/U = {_number(1 / speed)} τ)")
    shear = data.get("shear")
    if shear and "rate" in shear:
        rate = float(shear["rate"])
        if math.isclose(rate, 1.0):
            return "τ = 1/γ̇ (strain units): shear rate γ̇ = 1/τ"
        return f"τ set by the shear rate γ̇ = {_number(rate)}/τ (1/γ̇ = {_number(1 / rate)} τ)"
    velocity = (data.get("initial") or {}).get("velocity") or {}
    temperature = float(velocity.get("temperature", 0.0))
    if temperature > 0:
        if math.isclose(temperature, 1.0):
            return "τ = d √(m/T₀): initial temperature T₀ = 1 m d²/τ²"
        return (f"τ set by the initial temperature T₀ = {_number(temperature)} m d²/τ² "
                f"(d √(m/T₀) = {_number(temperature ** -0.5)} τ)")
    scale = abs(float(velocity.get("scale", 0.0)))
    if scale > 0:
        return f"τ set by the initial speed scale U = {_number(scale)} d/τ"
    return ("τ: the time unit of the scene's numbers (no gravity, moving wall, shear or "
            "initial temperature fixes it; see the scene file's header)")
