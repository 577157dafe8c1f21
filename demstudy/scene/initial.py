"""Initial particle states built from a scene, identical for every engine.

Dimensionless particle units: d = 1, m = 1, g = 1 when gravity acts. Deterministic for a
given ``run.seed``. Centres are kept at least ``MARGIN`` inside walls and box faces, because
some engines (LIGGGHTS) crash on particles lying exactly on a boundary.
"""

from __future__ import annotations

import math
import warnings
from dataclasses import dataclass

import numpy as np

from .base import SceneError
from .particle_file import particle_file_problems, read_particle_file
from .scene import Scene

MARGIN = 1e-3
#: Campbell's (1982) 7th-order least-squares fit to a chute velocity profile, F(y/H).
CAMPBELL_CHUTE_FIT = (0.2018029, 3.5299215, -15.2262754, 47.4364204, -88.1786499,
                      93.5828476, -51.8336868, 11.4877520)


@dataclass
class InitialState:
    position: np.ndarray  # (N, dim)
    velocity: np.ndarray  # (N, dim)
    angular_velocity: np.ndarray  # (N, 1) in 2D, (N, 3) in 3D
    diameter: np.ndarray  # (N,)

    @property
    def mass(self) -> np.ndarray:
        return self.diameter ** self.position.shape[1]


def y_range(scene: Scene, radius: float = 0.5) -> tuple[float, float]:
    """The interval available to the centres of particles of ``radius`` along y."""
    if scene.y_periodic:
        return 0.0, scene.box.size[1]
    lo = scene.wall_surface("lower") + radius + MARGIN
    top = scene.wall_surface("upper") if scene.wall("upper") else scene.box.size[1]
    hi = top - radius - MARGIN
    return lo, hi


def build_initial_state(scene: Scene) -> InitialState:
    rng = np.random.default_rng(scene.run.seed)
    dim, n = scene.dimension, scene.n_particles
    spread = scene.particles.diameter_spread
    diameter = particle_diameters(scene, rng)
    init = scene.initial
    if init.placement == "lattice":
        position = _campbell_lattice(scene, rng, d_max=1.0 + spread / 2)
    elif init.placement == "file":
        position, velocity = _from_file(scene)
    else:
        position = _random_placement(scene, rng, diameter)
    if init.placement != "file" or velocity is None:
        velocity = _velocity_profile(scene, position, rng)
    spin_dofs = 1 if dim == 2 else 3
    angular = np.zeros((n, spin_dofs))
    temperature = init.velocity.temperature
    if temperature > 0:
        mass = diameter**dim
        noise = rng.normal(size=(n, dim)) * np.sqrt(temperature / mass)[:, None]
        # remove the noise's momentum (mass-weighted: diameters may differ)
        velocity = velocity + noise - (mass[:, None] * noise).sum(axis=0) / mass.sum()
        inertia = scene.inertia_k * mass * diameter**2 / 4
        if scene.rotation_matters and scene.inertia_k > 0:
            angular = rng.normal(size=(n, spin_dofs)) * np.sqrt(temperature / inertia)[:, None]
    return InitialState(position, velocity, angular, diameter)


def particle_diameters(scene: Scene, rng: np.random.Generator) -> np.ndarray:
    """Diameters: 1, or uniform in 1 ± diameter_spread/2 (the first draw from ``rng``, so
    validation can check a particle file against the very diameters a run uses)."""
    n, spread = scene.n_particles, scene.particles.diameter_spread
    return 1.0 + spread * (rng.random(n) - 0.5) if spread > 0 else np.ones(n)


def _campbell_lattice(scene: Scene, rng: np.random.Generator, d_max: float = 1.0) -> np.ndarray:
    """Campbell's COL007: square (cubic) lattice jittered by at most the gap (s − d_max)/2."""
    init, dim = scene.initial, scene.dimension
    s = init.spacing
    layers = (init.layers or 1) if dim == 3 else 1
    cols, rows, deps = np.meshgrid(
        np.arange(init.columns), np.arange(init.rows), np.arange(layers), indexing="ij"
    )
    lower = 0.0 if scene.y_periodic else scene.wall_surface("lower")
    pos = [s / 2 + s * cols.ravel(), lower + s / 2 + s * rows.ravel()]
    if dim == 3:
        pos.append(s / 2 + s * deps.ravel())
    position = np.stack(pos, axis=1)
    if init.jitter:
        gap = max(0.0, (s - d_max) / 2 - MARGIN / 2)
        position += gap * rng.uniform(-1.0, 1.0, size=position.shape)
    # order by row then column, as Campbell numbered his particles
    order = np.lexsort([position[:, 0], np.floor((position[:, 1] - lower) / s)])
    return position[order]


#: Random sequential addition (RSA) up to these solid fractions, Lubachevsky–Stillinger growth
#: (a fluid) above: about two thirds of RSA's jamming limits (φ ≈ 0.38 spheres, 0.547 discs),
#: where RSA still fills a box in milliseconds and its structure is close to the fluid's.
RSA_LIMIT = {2: 0.35, 3: 0.25}


def _random_placement(scene: Scene, rng: np.random.Generator, diameter: np.ndarray) -> np.ndarray:
    """Random non-overlapping centres: random sequential addition when dilute, otherwise a
    fluid grown from a dilute random state (:mod:`demstudy.scene.fluid_start`). Only when the
    growth jams below the target (too dense for a fluid) or the box is too thin for it, a
    random subset of a close-packed lattice (hexagonal / fcc), jittered within its gaps."""
    dim, n = scene.dimension, scene.n_particles
    d_max = float(diameter.max())
    lo_y, hi_y = y_range(scene, radius=d_max / 2)
    lo = np.array([0.0, lo_y] + ([0.0] if dim == 3 else []))
    hi = np.array([scene.box.size[0], hi_y] + ([scene.box.size[2]] if dim == 3 else []))
    periodic = np.array([True, scene.y_periodic] + ([True] if dim == 3 else []))
    if scene.solid_fraction < RSA_LIMIT[dim]:
        found = _sequential_addition(n, lo, hi, periodic, d_max, rng)
        if found is not None:
            return found
    return _fluid_or_lattice(scene, rng, diameter, lo, hi, periodic)


def _fluid_or_lattice(scene, rng, diameter, lo, hi, periodic) -> np.ndarray:
    from .fluid_start import grow_fluid  # noqa: PLC0415 - loads the native module

    walls = None
    if not scene.y_periodic:
        top = scene.wall_surface("upper") if scene.wall("upper") else scene.box.size[1]
        walls = (scene.wall_surface("lower") + MARGIN, top - MARGIN)
    reason = ""
    try:
        grown = grow_fluid(diameter, lo, hi, periodic, walls, rng)
        if grown.reached:
            return grown.position
        reason = "the growth jammed before the target solid fraction"
    except ValueError as err:
        reason = str(err)
    warnings.warn(f"placement = 'random' at solid fraction {scene.solid_fraction:.3g}: no fluid "
                  f"start ({reason}); using a random subset of a close-packed lattice, which "
                  "is crystalline", stacklevel=3)
    return _lattice_subset(scene.n_particles, lo, hi, periodic, float(diameter.max()), rng)


def _sequential_addition(
    n, lo, hi, periodic, d_max, rng, max_tries: int = 200
) -> np.ndarray | None:
    from scipy.spatial import cKDTree  # noqa: PLC0415 - scipy.spatial costs ~0.1 s to import

    lengths = hi - lo
    accepted = np.empty((0, len(lo)))
    remaining = n
    for _ in range(max_tries):
        trial = lo + rng.random((max(2 * remaining, 64), len(lo))) * lengths
        # accept greedily among the batch, then against the already accepted set
        keep = []
        tree_box = np.where(periodic, lengths, 1e12)
        shifted = trial - lo
        tree_old = cKDTree(accepted - lo, boxsize=tree_box) if len(accepted) else None
        tree_new = cKDTree(shifted, boxsize=tree_box)
        clash = set()
        for i, j in tree_new.query_pairs(d_max):
            clash.add(max(i, j))
        for i in range(len(trial)):
            if i in clash:
                continue
            if tree_old is not None and tree_old.query_ball_point(shifted[i], d_max):
                continue
            keep.append(i)
            if len(keep) == remaining:
                break
        accepted = np.vstack([accepted, trial[keep]])
        remaining = n - len(accepted)
        if remaining == 0:
            return accepted
    return None


def _lattice_subset(n, lo, hi, periodic, d_max, rng) -> np.ndarray:
    dim = len(lo)
    lengths = hi - lo
    # shrink the nearest-neighbour distance until the lattice holds n sites (never below d_max)
    for a in np.geomspace(3.0 * d_max, d_max * (1 + 1e-6), 400):
        sites = _close_packed(a, lengths, periodic)
        if len(sites) >= n:
            break
    else:
        raise ValueError(
            f"cannot place {n} particles of diameter {d_max:g} without overlap in the box"
        )
    chosen = sites[rng.choice(len(sites), size=n, replace=False)]
    gap = max(0.0, (a - d_max) / 2 - 1e-9)
    jitter = rng.uniform(-1, 1, size=chosen.shape) * gap / math.sqrt(dim)
    out = chosen + jitter
    # keep bounded axes inside
    for ax in range(dim):
        if not periodic[ax]:
            out[:, ax] = np.clip(out[:, ax], 0.0, lengths[ax])
    return lo + np.where(periodic, np.mod(out, lengths), out)


def _close_packed(a: float, lengths: np.ndarray, periodic: np.ndarray) -> np.ndarray:
    """Hexagonal (2D) or fcc (3D) sites with nearest-neighbour distance ≥ a in the region."""
    dim = len(lengths)
    if dim == 2:
        cell = np.array([a, a * math.sqrt(3)])
        basis = np.array([[0.0, 0.0], [0.5, 0.5]])
    else:
        cell = np.full(3, a * math.sqrt(2))
        basis = np.array([[0, 0, 0], [0.5, 0.5, 0], [0.5, 0, 0.5], [0, 0.5, 0.5]], float)
    counts = []
    for ax in range(dim):
        if periodic[ax]:
            counts.append(int(math.floor(lengths[ax] / cell[ax] + 1e-12)))
        else:
            counts.append(int(math.floor(lengths[ax] / cell[ax])) + 1)
    if min(counts) < 1:
        return np.empty((0, dim))
    grids = np.meshgrid(*[np.arange(c) for c in counts], indexing="ij")
    origins = np.stack([g.ravel() for g in grids], axis=1).astype(float)
    sites = (origins[:, None, :] + basis[None, :, :]).reshape(-1, dim) * cell
    inside = np.all((sites <= lengths + 1e-12) | periodic, axis=1)
    return sites[inside]


def _from_file(scene: Scene) -> tuple[np.ndarray, np.ndarray | None]:
    """Positions (and velocities, if the file has 2·dim columns) from ``initial.path``; the
    scene's validation has checked the file (:mod:`demstudy.scene.particle_file`), but it
    may have changed since, so check again."""
    dim = scene.dimension
    problems = particle_file_problems(scene)
    if problems:
        raise SceneError(str(scene.initial.path), problems)
    data = read_particle_file(scene.initial.path).data
    velocity = data[:, dim:].copy() if data.shape[1] == 2 * dim else None
    return data[:, :dim].copy(), velocity


def _velocity_profile(scene: Scene, position: np.ndarray, rng: np.random.Generator) -> np.ndarray:
    v = scene.initial.velocity
    n, dim = position.shape
    velocity = np.zeros((n, dim))
    y = position[:, 1]
    if v.profile == "uniform":
        u = np.full(n, v.scale)
    elif v.profile == "campbell-chute":
        init = scene.initial
        height = (init.spacing * init.rows - init.spacing / 2) if init.spacing else y.max()
        z = (y - scene.wall_surface("lower")) / height
        u = np.polynomial.polynomial.polyval(z, CAMPBELL_CHUTE_FIT) * v.scale
    elif v.profile == "linear":
        if scene.shear is not None:
            u = scene.shear.rate * (y - scene.box.size[1] / 2)
        else:
            lo, hi = scene.wall_position("lower"), scene.wall_position("upper")
            u_lo, u_hi = scene.wall("lower").velocity, scene.wall("upper").velocity
            u = u_lo + (u_hi - u_lo) * (y - lo) / (hi - lo)
    else:
        u = np.zeros(n)
    velocity[:, 0] = u
    if v.perturbation > 0:
        kick = rng.uniform(-1.0, 1.0, size=(n, dim)) * v.perturbation * np.abs(u)[:, None]
        velocity += kick
    return velocity
