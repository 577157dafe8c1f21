"""`demstudy plot`: one figure per kind from results files written by the real writers and
analyses (synthetic frames through `demstudy analyze`, and a short event-driven homogeneous
cooling run); the plotted Line2D data must equal the stored datasets or the theory functions.
Dimensionless particle units: d = 1, m = 1, g = 1 with gravity."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from demstudy.analysis.derived import campbell_depth
from demstudy.cli import main
from demstudy.io.results import Results, read_results, write_results
from demstudy.plot import plot_profiles
from demstudy.plots import KINDS, draw, output_path, parse_kinds
from demstudy.plots.common import Run
from demstudy.plots.waves import dominant_plane, spectrum_image
from demstudy.scene import load_scene, scene_to_toml

INPUTS = Path(__file__).resolve().parent.parent / "inputs"
CHUTE = INPUTS / "campbell1982" / "chute-30.toml"
COUETTE = INPUTS / "campbell1982" / "couette-noslip.toml"
CHANNEL_3D = INPUTS / "malik2008" / "waves-phi0.15-L45W15H15.toml"
ATTRS = {"engine": "synthetic", "engine_version": "test 1", "equilibration_end": 0.0}


def _frames(scene, n, frames, y_range, rng, shear=0.0):
    dim, size = scene.dimension, np.asarray(scene.box.size, float)
    lo, hi = np.full(dim, 0.5), size - 0.5
    lo[1], hi[1] = y_range
    pos = rng.uniform(lo, hi, (frames, n, dim))
    vel = rng.normal(scale=0.5, size=(frames, n, dim))
    vel[..., 0] += shear * pos[..., 1]
    return {"time": np.arange(frames, dtype=float), "position": pos, "velocity": vel,
            "angular_velocity": rng.normal(size=(frames, n, 1 if dim == 2 else 3)),
            "radius": np.full((frames, n), 0.5), "box_lo": np.zeros((frames, dim)),
            "box_hi": np.tile(size, (frames, 1)), "tilt": np.zeros(frames)}


def _collision_log(rng, m, height, t_end):
    n = rng.normal(size=(m, 2))
    n /= np.linalg.norm(n, axis=1)[:, None]
    pos = np.stack([rng.uniform(0, 4.8, m), rng.uniform(0.5, height, m)], axis=1)
    return {"time": np.sort(rng.uniform(0, t_end, m)), "kind": np.zeros(m, np.int8),
            "position": pos, "normal": n, "branch": n, "impulse": -n,
            "velocity": rng.normal(size=(m, 2)), "spin_velocity": rng.normal(size=(m, 2))}


@pytest.fixture(scope="module")
def chute(tmp_path_factory):
    """A 2D chute (gravity, open top) with profiles, stress (kinetic + collisional, lower wall,
    momentum balance), vdf, gr, vcorr, waves and angles; no lambda (3D only)."""
    path = tmp_path_factory.mktemp("chute") / "chute.h5"
    scene = load_scene(CHUTE)
    rng = np.random.default_rng(3)
    n_frames, n_bins = 12, 40
    frames = _frames(scene, 40, n_frames, (0.5, 12.0), rng, shear=0.3)
    force = np.tile([-3.0, -20.0], (n_frames, 1)) + rng.normal(scale=0.5, size=(n_frames, 2))
    coll = rng.normal(scale=0.1, size=(n_bins, 2, 2))
    write_results(path, Results(
        attrs={**ATTRS, "scene_toml": scene_to_toml(scene), "scene_name": scene.meta.name},
        timeseries={"time": frames["time"], "wall_force_lower": force},
        frames=frames,
        groups={"collisions": _collision_log(rng, 3000, 12.0, n_frames - 1.0),
                "stress": {"collisional": coll, "collisional_err": np.abs(coll) * 0.1}}))
    assert main(["analyze", str(path), "--what", "profiles,vdf,gr,vcorr,waves"]) == 0
    assert main(["analyze", str(path), "--what", "angles,stress"]) == 0
    return path


@pytest.fixture(scope="module")
def cooling(tmp_path_factory):
    """A real homogeneous cooling run: 1000 smooth spheres, φ = 0.1, e = 0.8, T0 = 1 in a
    periodic cube, `demstudy run --engine edmd` up to t = 30 ≈ 3 t0 (about 2 s)."""
    from edmd_helpers import make_scene

    folder = tmp_path_factory.mktemp("cooling")
    scene = make_scene(3, 0.1, 1000, seed=4, e=0.8, production=30.0, sample=1.0,
                       extra='[meta]\nname = "hcs-test"')
    (folder / "hcs.toml").write_text(scene_to_toml(scene))
    path = folder / "hcs.h5"
    assert main(["run", str(folder / "hcs.toml"), "--engine", "edmd", "--out", str(path),
                 "--quiet"]) == 0
    return path


@pytest.fixture(scope="module")
def channel(tmp_path_factory):
    """A 3D channel (walls at y = 0, 15) with lambda and waves only."""
    path = tmp_path_factory.mktemp("channel") / "channel.h5"
    scene = load_scene(CHANNEL_3D)
    frames = _frames(scene, 300, 4, (0.5, 14.5), np.random.default_rng(5))
    write_results(path, Results(attrs={**ATTRS, "scene_toml": scene_to_toml(scene),
                                       "scene_name": scene.meta.name}, frames=frames))
    assert main(["analyze", str(path), "--what", "lambda,waves"]) == 0
    return path


@pytest.fixture(scope="module")
def freepath(tmp_path_factory):
    """A results file with only ``/statistics/freepath``, from the real analysis
    (FreePath fed with flight_chunks, Enskog references from a profile overlay) on synthetic
    exponential flights (mean time 2, speed 1.5) of 3000 particles started in y ∈ [0, 4],
    written by write_results."""
    from demstudy.analysis.collisions import FreePath, flight_chunks

    rng = np.random.default_rng(7)
    ends = rng.random((3000, 1)) + np.cumsum(rng.exponential(2.0, (3000, 30)), axis=1)
    starts, taus = ends[:, :-1], np.diff(ends, axis=1)
    done = ends[:, 1:] <= 50.0
    starts, taus = starts[done], taus[done]
    y = rng.uniform(0.0, 4.0, taus.size)
    flights = {"t0": 0.0, "t1": 50.0, "start_time": starts, "tau": taus, "length": 1.5 * taus,
               "start": np.column_stack([np.zeros_like(y), y]), "event_time": starts,
               "event_y": y}
    edges = np.linspace(0.0, 4.0, 5)
    ana = FreePath(edges, 24.0, 16.0, width=4.0).run(flight_chunks(flights, 16)).finish()
    ana.overlay({"y": 0.5 * (edges[1:] + edges[:-1]), "solid_fraction": np.full(4, 0.1),
                 "temperature": np.full(4, 1.0), "velocity": np.zeros((4, 3))},
                cross_section=100.0)
    ana.attrs["knudsen_width_is"] = "wall gap"
    path = tmp_path_factory.mktemp("freepath") / "fp.h5"
    return write_results(path, Results(attrs=dict(ATTRS), groups={
        "statistics/freepath": ana.results}, group_attrs={"statistics/freepath": ana.attrs}))


def line(fig, gid):
    """The data line (the first Line2D) carrying ``gid``."""
    found = [ln for ax in fig.axes for ln in ax.get_lines() if ln.get_gid() == gid]
    assert found, f"no line {gid!r}"
    return found[0]


def same(ln, x, y):
    np.testing.assert_array_equal(np.asarray(ln.get_xdata(), float), np.asarray(x, float))
    np.testing.assert_array_equal(np.asarray(ln.get_ydata(), float), np.asarray(y, float))


def footer(fig):
    return " ".join(t.get_text() for t in fig.texts)


def test_all_kinds_write_pngs_and_skip_the_absent_one(chute, tmp_path, capsys):
    out = tmp_path / "fig.png"
    assert main(["plot", str(chute), "--kind", "all", "-o", str(out)]) == 0
    cap = capsys.readouterr()
    drawn = [k for k in KINDS if k not in ("freepath", "lambda", "cooling")]
    for kind in drawn:
        png = tmp_path / f"fig-{kind}.png"
        assert f"figure: {png}" in cap.out
        assert png.read_bytes()[:4] == b"\x89PNG" and png.stat().st_size > 20_000, kind
    assert not (tmp_path / "fig-lambda.png").exists()
    assert not (tmp_path / "fig-cooling.png").exists()  # a chute is not a cooling run
    assert not (tmp_path / "fig-freepath.png").exists()  # its log has no particle indices
    notices = [ln for ln in cap.err.splitlines() if ln]
    assert len(notices) == 3 and "freepath skipped" in notices[0]
    assert "--what freepath" in notices[0]
    assert "lambda skipped" in notices[1] and "--what lambda" in notices[1]
    assert "cooling skipped" in notices[2] and "homogeneous cooling" in notices[2]
    assert "Traceback" not in cap.err


def test_profiles_and_stress_plot_the_stored_data(chute, tmp_path):
    run = Run.load(chute)
    prof = read_results(chute).profiles
    name = chute.name
    fig = draw("profiles", [run])
    occupied = prof["solid_fraction"] > 1e-3
    same(line(fig, f"{name}:solid_fraction"), prof["solid_fraction"], prof["y"])
    same(line(fig, f"{name}:velocity"), prof["velocity"][occupied, 0], prof["y"][occupied])
    same(line(fig, f"{name}:temperature"), prof["temperature"][occupied], prof["y"][occupied])
    assert "d = 1, m = 1, g = 1" in footer(fig) and "synthetic (test 1)" in footer(fig)
    assert "gravity acts" in footer(fig)

    scaled = draw("profiles", [run], scaled=True)  # open top: Campbell's flow depth
    depth = campbell_depth(prof, 0.0)
    same(line(scaled, f"{name}:solid_fraction"), prof["solid_fraction"], prof["y"] / depth)
    assert "flow depth" in scaled.axes[0].get_ylabel()

    st = read_results(chute).groups["statistics/stress"]
    fig = draw("stress", [run])
    for key in ("kinetic", "collisional", "total"):
        same(line(fig, f"{name}:{key}:xy"), st[key][:, 0, 1], st["y"])
        same(line(fig, f"{name}:{key}:yy"), st[key][:, 1, 1], st["y"])
    same(line(fig, f"{name}:wall_lower:yy"), [st["wall_lower"][1]], [st["edges"][0]])
    same(line(fig, f"{name}:wall_lower:xy"), [st["wall_lower"][0]], [st["edges"][0]])
    same(line(fig, f"{name}:balance:xy"), -st["balance_tau_xy"], st["y"])
    same(line(fig, f"{name}:balance:yy"), st["balance_tau_yy"], st["y"])


def test_distributions_and_correlations_plot_the_stored_data(chute):
    run = Run.load(chute)
    groups = read_results(chute).groups
    name = chute.name

    vdf = groups["statistics/vdf"]
    fig = draw("vdf", [run], bins=[2, 5])
    for b in (1, 4):
        for k, x in enumerate(("X1", "X2", "X3", "X4", "X5")):
            same(line(fig, f"{name}:X:{b}:{x}"), vdf["X_centres"], vdf["X"][b, k])
        for c, comp in enumerate(("u", "v", "omega_z")):
            same(line(fig, f"{name}:malik_P:{b}:{comp}"), vdf["malik_centres"],
                 vdf["malik_P"][b, c])
    same(line(fig, f"{name}:X_reference:-:X4"), vdf["X_centres"], vdf["X_reference"][3])
    same(line(fig, f"{name}:gaussian:-:v"), vdf["malik_centres"], vdf["gaussian"])

    ang = groups["statistics/angles"]
    fig = draw("angles", [run], bins=[3])
    deg = np.degrees(ang["theta"])
    for conv in ("text", "listing"):
        same(line(fig, f"{name}:p_{conv}:2"), deg, ang[f"p_{conv}"][2])
        same(line(fig, f"{name}:sj_{conv}_R:2"), deg, ang[f"sj_{conv}_R"][2])
    assert np.all(np.isfinite(ang["sj_text_R"][2]))

    gr = groups["statistics/gr"]
    fig = draw("gr", [run])
    same(line(fig, f"{name}:gr:0"), gr["r"], gr["g"][0])

    vc = groups["statistics/vcorr"]
    fig = draw("vcorr", [run])  # default bins: first occupied, fourth, middle
    first = int(np.flatnonzero(vc["count"] > 0)[0])
    for a in (0, 1):
        same(line(fig, f"{name}:C:{first}:{a}"), vc["r"], vc["C"][first, a])
        same(line(fig, f"{name}:C:{first + 3}:{a}"), vc["r"], vc["C"][first + 3, a])
    assert vc["C_offdiag"].shape == (vc["C"].shape[0], 1, vc["r"].size)  # 2D: xy only
    for b in (first, first + 3):
        same(line(fig, f"{name}:C_offdiag:{b}:0"), vc["r"], vc["C_offdiag"][b, 0])
    titles = [ax.get_title() for ax in fig.axes if ax.get_visible()]
    assert titles == ["C_xx(r)", "C_yy(r)", "C_xy(r)"]


def test_waves_plot_spectrum_field_and_series(chute, channel):
    for path in (chute, channel):
        run = Run.load(path)
        data, attrs = run.group("waves")
        plane = dominant_plane(data, attrs)
        fig = draw("waves", [run])
        mesh = [c for ax in fig.axes for c in ax.collections
                if c.get_gid() == f"{path.name}:spectrum_{plane}"]
        _ka, _kb, power = spectrum_image(data, plane)
        np.testing.assert_array_equal(np.ma.getdata(mesh[0].get_array()).ravel(),
                                      np.ma.getdata(power).ravel())
        assert mesh[0].norm.__class__.__name__ == "LogNorm"
        assert np.ma.getmaskarray(power)[list(_kb).index(0), list(_ka).index(0)]  # (0,0) masked
        for j in range(data[f"series_modes_{plane}"].shape[0]):
            same(line(fig, f"{path.name}:series_{plane}:{j}"), data["series_time"],
                 data[f"series_{plane}"][:, j])
    # 3D: no dominant family in a random gas, the xy plane is drawn
    data, attrs = Run.load(channel).group("waves")
    assert dominant_plane(data, attrs) == "xy"
    fake = dict(data, dominant_yz=np.array([[1, 1]]))
    assert dominant_plane(fake, attrs) == "yz"


def test_lambda_and_absent_kinds_give_notices_and_exit_0(channel, tmp_path, capsys):
    run = Run.load(channel)
    lam = read_results(channel).groups["statistics/lambda"]
    fig = draw("lambda", [run])
    mask = lam["count"] > 0
    same(line(fig, f"{channel.name}:lambda"), lam["lambda"][mask], lam["y"][mask])
    assert "gravity acts here" in footer(fig)

    out = tmp_path / "f.png"
    assert main(["plot", str(channel), "--kind", "profiles,lambda", "--kind", "vdf",
                 "-o", str(out)]) == 0
    cap = capsys.readouterr()
    assert cap.out.strip() == f"figure: {tmp_path / 'f-lambda.png'}"
    assert (tmp_path / "f-lambda.png").stat().st_size > 10_000
    notices = cap.err.strip().splitlines()
    assert len(notices) == 2 and "profiles skipped" in notices[0] and "vdf skipped" in notices[1]

    assert main(["plot", str(channel), "--kind", "stress", "-o", str(out)]) == 0
    cap = capsys.readouterr()
    assert not out.exists() and "stress skipped" in cap.err and "no figure" in cap.err
    assert "Traceback" not in cap.err


def test_unknown_kind_is_refused_with_exit_2(chute, capsys):
    assert main(["plot", str(chute), "--kind", "profiles,spectra"]) == 2
    err = capsys.readouterr().err
    assert "'spectra'" in err and all(k in err for k in KINDS) and "Traceback" not in err
    with pytest.raises(ValueError, match="allowed"):
        parse_kinds(["gr,nope"])


def test_scaled_profiles_between_walls_and_overlay(chute, tmp_path):
    """Couette cell: H = the wall gap; two files overlay in one figure; plot_profiles keeps
    its signature (returns the path)."""
    scene = load_scene(COUETTE)
    edges = np.linspace(0.0, 12.0, 13)
    y = 0.5 * (edges[1:] + edges[:-1])
    prof = {"y": y, "edges": edges, "solid_fraction": np.full(12, 0.5),
            "velocity": np.stack([y / 12, np.zeros(12)], axis=1),
            "temperature": np.full(12, 0.1), "rotational_temperature": np.full(12, 0.05)}
    path = write_results(tmp_path / "couette.h5", Results(
        attrs={**ATTRS, "scene_toml": scene_to_toml(scene), "scene_name": scene.meta.name},
        profiles=prof, profile_attrs={"axis": "y"}))
    fig = draw("profiles", [Run.load(path), Run.load(chute)], scaled=True)
    same(line(fig, "couette.h5:velocity"), y / 12, y / 12.0)
    assert "see the legend" in fig.axes[0].get_ylabel()  # gap and flow depth mixed
    labels = fig.axes[0].get_legend_handles_labels()[1]
    assert any("H = 12" in label for label in labels)
    fig = draw("profiles", [Run.load(path)], scaled=True)
    assert "gap between the walls" in fig.axes[0].get_ylabel()
    assert "no gravity here" in footer(fig)
    out = plot_profiles([path], tmp_path / "p.png")
    assert out == tmp_path / "p.png" and out.stat().st_size > 10_000
    assert main(["plot", str(path), "--scaled", "-o", str(tmp_path / "s.png")]) == 0
    assert (tmp_path / "s.png").stat().st_size > 10_000


def test_output_names():
    assert output_path("a/fig.png", "vdf", False) == Path("a/fig.png")
    assert output_path("a/fig.png", "vdf", True) == Path("a/fig-vdf.png")
    assert output_path("a/fig", "gr", True) == Path("a/fig-gr.png")
    assert output_path(None, "waves", True) == Path("waves.png")


def test_equation_of_state_plots_chi_against_nu(chute):
    """χ per bin from the stored total P_yy and the profiles (derived.equation_of_state), at
    each bin's ν; the theory curve is campbell_chi for the scene's e."""
    from demstudy.analysis.derived import equation_of_state
    from demstudy.theory import campbell_chi

    run = Run.load(chute)
    res = read_results(chute)
    st, prof = res.groups["statistics/stress"], res.profiles
    chi, _err = equation_of_state(prof, st["total"][:, 1, 1], st["total_err"][:, 1, 1])
    nu = prof["solid_fraction"]
    ok = np.isfinite(chi) & (nu > 0.02)
    assert ok.sum() >= 3
    fig = draw("eos", [run])
    same(line(fig, f"{chute.name}:chi"), nu[ok], chi[ok])
    theory = line(fig, f"{chute.name}:chi_theory")
    x = np.asarray(theory.get_xdata(), float)
    e = run.scene.contact.restitution
    np.testing.assert_allclose(theory.get_ydata(), campbell_chi(x, 2, e), rtol=1e-12)
    assert "Henderson" in fig._suptitle.get_text()


def test_vcorr_plot_draws_the_three_off_diagonal_components_in_3d(channel, tmp_path):
    """3D: C_xy, C_xz, C_yz below C_xx, C_yy, C_zz, each the stored C_offdiag row."""
    assert main(["analyze", str(channel), "--what", "vcorr", "--out",
                 str(tmp_path / "vc.h5")]) == 0
    path = tmp_path / "vc.h5"
    vc = read_results(path).groups["statistics/vcorr"]
    fig = draw("vcorr", [Run.load(path)], bins=[2])
    for p in range(3):
        same(line(fig, f"vc.h5:C_offdiag:1:{p}"), vc["r"], vc["C_offdiag"][1, p])
    titles = [ax.get_title() for ax in fig.axes]
    assert titles[3:] == ["C_xy(r)", "C_xz(r)", "C_yz(r)"]


def test_cooling_plot_overlays_haff_on_a_real_edmd_run(cooling, chute, tmp_path, capsys):
    """T/T0 from the kinetic energy (centre-of-mass motion removed, dim (N − 1) degrees of
    freedom) and Haff's T0/(1 + t/t0)² from demstudy.theory with the scene's ν and e, both
    on log–log axes; the run follows Haff within 10 % up to 3 t0 (a t0 off by 2 would miss
    by > 60 %). Other runs skip the kind with a notice."""
    from demstudy.theory import haff_t0, haff_temperature

    run = Run.load(cooling)
    ts, scene = read_results(cooling).timeseries, run.scene
    n = scene.n_particles
    temp = (2 * ts["kinetic_energy"] - (ts["momentum"] ** 2).sum(1) / n) / (3 * (n - 1))
    t = ts["time"] - ts["time"][0]
    fig = draw("cooling", [run])
    same(line(fig, "hcs.h5:temperature"), t[1:], temp[1:] / temp[0])
    haff = line(fig, "hcs.h5:haff")
    nu, e = scene.solid_fraction, scene.contact.restitution
    assert (nu, e) == (pytest.approx(0.1), 0.8)
    np.testing.assert_array_equal(haff.get_xdata(), t[1:])
    np.testing.assert_allclose(haff.get_ydata(),
                               haff_temperature(t[1:], nu, temp[0], 3, e) / temp[0], rtol=1e-12)
    t0 = haff_t0(nu, temp[0], 3, e)
    assert f"t0 = {t0:.3g}" in haff.get_label() and t[-1] > 3 * t0 * 0.95
    assert fig.axes[0].get_xscale() == fig.axes[0].get_yscale() == "log"
    ratio = temp[1:] / temp[0] / np.asarray(haff.get_ydata())
    assert temp[-1] / temp[0] < 0.1 and np.all(np.abs(ratio - 1) < 0.1)
    assert "initial temperature sets the time scale" in footer(fig)

    out = tmp_path / "c.png"  # `all` includes cooling for a cooling run (the chute skips it)
    assert main(["plot", str(cooling), "--kind", "all", "-o", str(out)]) == 0
    cap = capsys.readouterr()
    assert f"figure: {tmp_path / 'c-cooling.png'}" in cap.out
    assert (tmp_path / "c-cooling.png").stat().st_size > 20_000
    assert "cooling skipped" not in cap.err and "Traceback" not in cap.err
    assert main(["plot", str(chute), "--kind", "cooling", "-o", str(out)]) == 0
    cap = capsys.readouterr()
    assert not out.exists() and "cooling skipped" in cap.err and "no figure" in cap.err


def test_freepath_plots_the_stored_pdfs_and_the_exponentials(freepath, chute, tmp_path, capsys):
    """P(λ), P(τ) per chosen bin equal the stored rows; the dashed reference is
    exp(−x/⟨x⟩)/⟨x⟩ with the bin's stored mean; the legend states ⟨λ⟩, Kn and Enskog's λ;
    `all` draws the kind for a file that has it (and only it)."""
    from demstudy.theory import mean_free_path

    fp = read_results(freepath).groups["statistics/freepath"]
    assert np.all(fp["flights"] > 0)
    fig = draw("freepath", [Run.load(freepath)], bins=[1, 3])
    for b in (0, 2):
        for x, mean in (("lambda", "mean_free_path"), ("tau", "mean_free_time")):
            same(line(fig, f"fp.h5:p_{x}:{b}"), fp[x], fp[f"p_{x}"][b])
            ref = line(fig, f"fp.h5:exp_{x}:{b}")
            np.testing.assert_array_equal(ref.get_xdata(), fp[x])
            m = fp[mean][b]
            np.testing.assert_allclose(ref.get_ydata(), np.exp(-fp[x] / m) / m, rtol=1e-12)
            assert ref.get_linestyle() == "--"
        assert fp["mean_free_path"][b] == pytest.approx(3.0, rel=0.05)  # 1.5 x ⟨τ⟩ = 2
    assert all(ax.get_yscale() == "log" for ax in fig.axes)
    assert not any(ln.get_gid() == "fp.h5:p_lambda:1" for ax in fig.axes for ln in ax.lines)
    labels = " ".join(fig.axes[0].get_legend_handles_labels()[1])
    assert f"⟨λ⟩ = {fp['mean_free_path'][2]:.3g}" in labels
    assert f"Kn = {fp['knudsen'][2]:.3g}" in labels
    assert f"λ_E = {mean_free_path(0.1, 3):.3g}" in labels
    assert "W = 4 (wall gap)" in fig._suptitle.get_text()
    default = draw("freepath", [Run.load(freepath)])  # first, fourth and middle bin
    assert {ln.get_gid() for ln in default.axes[1].lines} >= {f"fp.h5:p_tau:{b}" for b in (0, 2, 3)}

    out = tmp_path / "f.png"
    assert main(["plot", str(freepath), str(chute), "--kind", "all", "-o", str(out)]) == 0
    cap = capsys.readouterr()
    assert f"figure: {tmp_path / 'f-freepath.png'}" in cap.out
    assert (tmp_path / "f-freepath.png").stat().st_size > 20_000
    assert "fp.h5: no /profiles: profiles skipped" in cap.err
    assert "chute.h5: no /statistics/freepath: freepath skipped" in cap.err
    assert "Traceback" not in cap.err


def test_profiles_draw_malik_cell_temperatures_dashed(channel, tmp_path):
    """`analyze --what profiles --z-cells 3` adds cell_temperature and
    cell_rotational_temperature: dashed next to the strip temperatures, in the strip's
    colour, labelled with the number of z-cells; without z-cells nothing is added."""
    path = tmp_path / "zc.h5"
    assert main(["analyze", str(channel), "--what", "profiles", "--z-cells", "3",
                 "--out", str(path)]) == 0
    res = read_results(path)
    prof = res.profiles
    assert int(res.profile_attrs["z_cells"]) == 3
    ok = prof["solid_fraction"] > 1e-3
    fig = draw("profiles", [Run.load(path)])
    for key in ("temperature", "rotational_temperature"):
        strip, cell = line(fig, f"zc.h5:{key}"), line(fig, f"zc.h5:cell_{key}")
        same(strip, prof[key][ok], prof["y"][ok])
        same(cell, prof[f"cell_{key}"][ok], prof["y"][ok])
        assert cell.get_linestyle() == "--" and cell.get_color() == strip.get_color()
        ax = cell.axes
        assert "3 z-cells (Malik)" in [t.get_text() for t in ax.get_legend().get_texts()]
    assert not np.array_equal(prof["cell_temperature"], prof["temperature"])

    strip_only = tmp_path / "strip.h5"
    assert main(["analyze", str(channel), "--what", "profiles", "--out", str(strip_only)]) == 0
    fig = draw("profiles", [Run.load(strip_only)])
    assert not any("cell_" in str(ln.get_gid()) for ax in fig.axes for ln in ax.lines)
