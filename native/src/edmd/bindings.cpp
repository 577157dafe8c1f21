// nanobind bindings of the event-driven engine core (demstudy._native.EventDriven).
// Dimensionless particle units: d = 1, m = 1.
#include <nanobind/nanobind.h>
#include <nanobind/ndarray.h>
#include <nanobind/stl/string.h>
#include <nanobind/stl/vector.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <string>
#include <vector>

#include "edmd/edmd.hpp"
#include "edmd/growth.hpp"

namespace nb = nanobind;
using namespace nb::literals;

namespace demstudy::edmd {

namespace {

using InArr = nb::ndarray<const double, nb::c_contig, nb::device::cpu>;
using NpArr = nb::ndarray<nb::numpy, double>;

template <typename T>
nb::ndarray<nb::numpy, T> owned(std::vector<std::size_t> shape) {
    std::size_t total = 1;
    for (auto s : shape) total *= s;
    T* data = new T[total > 0 ? total : 1]();
    nb::capsule owner(data, [](void* p) noexcept { delete[] static_cast<T*>(p); });
    return nb::ndarray<nb::numpy, T>(data, shape.size(), shape.data(), owner);
}

template <typename T>
nb::ndarray<nb::numpy, T> from_vector(const std::vector<T>& v, std::vector<std::size_t> shape) {
    auto out = owned<T>(shape);
    if (!v.empty()) std::memcpy(out.data(), v.data(), v.size() * sizeof(T));
    return out;
}

void require(bool ok, const std::string& what) {
    if (!ok) throw nb::value_error(what.c_str());
}

std::size_t rows(const InArr& a, std::size_t cols, const char* name) {
    const bool ok = (cols == 1 && a.ndim() == 1) ||
                    (a.ndim() == 2 && static_cast<std::size_t>(a.shape(1)) == cols);
    require(ok, std::string(name) + " has the wrong shape");
    return static_cast<std::size_t>(a.shape(0));
}

Rule parse_rule(nb::handle h, const char* who) {
    // {"e": .., "law": "constant"|"campbell-exp"|"gutt-piecewise", "speed", "e1", "e2",
    //  "crossover_speed", "tangential": "beta"|"coulomb"|"noslip", "beta", "mu", "beta0",
    //  "beta0_from_e": true -> β₀ = e of each collision}
    Rule r;
    nb::dict d = nb::cast<nb::dict>(h);
    auto num = [&](const char* key, double dflt) {
        return d.contains(key) ? nb::cast<double>(d[key]) : dflt;
    };
    r.e = num("e", 1.0);
    const std::string law = d.contains("law") ? nb::cast<std::string>(d["law"]) : "constant";
    if (law == "constant") r.law = Rule::kConstant;
    else if (law == "campbell-exp") r.law = Rule::kCampbellExp;
    else if (law == "gutt-piecewise") r.law = Rule::kGutt;
    else throw nb::value_error((std::string(who) + ": unknown law " + law).c_str());
    r.speed = num("speed", 1.0);
    r.e1 = num("e1", 1.0);
    r.e2 = num("e2", 1.0);
    r.crossover = num("crossover_speed", 1.0);
    const std::string tang =
        d.contains("tangential") ? nb::cast<std::string>(d["tangential"]) : "beta";
    if (tang == "beta") r.tangential = Rule::kBeta;
    else if (tang == "coulomb") r.tangential = Rule::kCoulomb;
    else if (tang == "noslip") r.tangential = Rule::kNoSlip;
    else throw nb::value_error((std::string(who) + ": unknown tangential rule " + tang).c_str());
    r.beta = num("beta", -1.0);
    r.mu = num("mu", 0.0);
    r.beta0 = num("beta0", 0.0);
    r.beta0_from_e = d.contains("beta0_from_e") && nb::cast<bool>(d["beta0_from_e"]);
    return r;
}

EventDriven* make(InArr pos, InArr vel, InArr omega, InArr diameter, InArr mass,
                  std::vector<double> box, int dim, double e, double beta, double inertia_k,
                  double tc, nb::kwargs options) {
    require(dim == 2 || dim == 3, "dim must be 2 or 3");
    require(box.size() == static_cast<std::size_t>(dim), "box needs dim lengths");
    const std::size_t n = rows(pos, dim, "positions (N, dim)");
    require(rows(vel, dim, "velocities (N, dim)") == n, "velocities: N rows");
    const std::size_t nrot = dim == 2 ? 1 : 3;
    require(rows(omega, nrot, "angular velocities (N, 1 in 2D / 3 in 3D)") == n,
            "angular velocities: N rows");
    require(rows(diameter, 1, "diameters (N,)") == n, "diameters: N entries");
    require(rows(mass, 1, "masses (N,)") == n, "masses: N entries");
    Params p;
    p.dim = dim;
    for (int a = 0; a < dim; ++a) {
        require(box[a] > 0.0 && std::isfinite(box[a]), "box lengths must be finite and positive");
        p.box[a] = box[a];
    }
    p.pair.e = e;
    p.pair.beta = beta;
    p.inertia_k = inertia_k;
    p.tc = tc;
    for (auto item : options) {
        const std::string key = nb::cast<std::string>(item.first);
        nb::handle v = item.second;
        if (key == "pair") {
            nb::dict d = nb::cast<nb::dict>(v);
            if (!d.contains("e")) d["e"] = e;
            if (!d.contains("beta")) d["beta"] = beta;
            p.pair = parse_rule(d, "pair");
        } else if (key == "gravity") {
            auto g = nb::cast<std::vector<double>>(v);
            require(g.size() == static_cast<std::size_t>(dim), "gravity needs dim components");
            for (int a = 0; a < dim; ++a) p.gravity[a] = g[a];
        } else if (key == "shear_rate") {
            p.shear_rate = nb::cast<double>(v);
        } else if (key == "periodic_y") {
            p.periodic_y = nb::cast<bool>(v);
        } else if (key == "y_range") {
            auto r = nb::cast<std::vector<double>>(v);
            require(r.size() == 2, "y_range needs (lo, hi)");
            p.y_lo = r[0];
            p.y_hi = r[1];
        } else if (key == "walls") {
            for (nb::handle wh : nb::cast<nb::list>(v)) {
                nb::dict d = nb::cast<nb::dict>(wh);
                const std::string side = nb::cast<std::string>(d["side"]);
                require(side == "lower" || side == "upper", "wall side: lower or upper");
                Wall& w = p.wall[side == "lower" ? 0 : 1];
                w.present = true;
                w.y0 = nb::cast<double>(d["position"]);
                w.vn = d.contains("normal_velocity") ? nb::cast<double>(d["normal_velocity"]) : 0.0;
                w.u[0] = d.contains("velocity") ? nb::cast<double>(d["velocity"]) : 0.0;
                w.u[2] = d.contains("velocity_z") ? nb::cast<double>(d["velocity_z"]) : 0.0;
                w.rule = parse_rule(d, "wall");
            }
        } else if (key == "stress_bins") {
            auto b = nb::cast<std::vector<double>>(v);
            require(b.size() == 3, "stress_bins needs (lo, width, count)");
            p.stress_lo = b[0];
            p.stress_width = b[1];
            EventDriven::check_stress_bins(b[0], b[1], b[2], "stress_bins");
            p.stress_bins = static_cast<std::int64_t>(b[2]);
        } else if (key == "fixed") {
            auto f = nb::cast<nb::ndarray<const std::int8_t, nb::c_contig, nb::device::cpu>>(v);
            require(f.size() == n, "fixed needs one int8 entry per particle");
            p.fixed.assign(f.data(), f.data() + n);
        } else if (key == "log_every") {
            p.log_every = nb::cast<std::int64_t>(v);
        } else if (key == "log_capacity") {
            p.log_capacity = nb::cast<std::int64_t>(v);
        } else {
            throw nb::value_error(("unknown option " + key).c_str());
        }
    }
    try {
        return new EventDriven(p, static_cast<std::int64_t>(n), pos.data(), vel.data(),
                               omega.data(), diameter.data(), mass.data());
    } catch (const std::invalid_argument& err) {
        throw nb::value_error(err.what());
    }
}

nb::dict state_dict(const EventDriven& s) {
    const auto st = s.get_state();
    const std::size_t n = static_cast<std::size_t>(s.size());
    nb::dict d;
    d["pos"] = from_vector(st.pos, {n, 3});
    d["vel"] = from_vector(st.vel, {n, 3});
    d["omega"] = from_vector(st.omega, {n, 3});
    d["last"] = from_vector(st.last, {n});
    d["count"] = from_vector(st.count, {n});
    d["cell"] = from_vector(st.cell, {n, 3});
    d["ev_time"] = from_vector(st.ev_time, {n + 1});
    d["ev_partner"] = from_vector(st.ev_partner, {n + 1});
    d["ev_count"] = from_vector(st.ev_count, {n + 1});
    d["co_time"] = from_vector(st.co_time, {n});
    d["co_partner"] = from_vector(st.co_partner, {n});
    d["co_count"] = from_vector(st.co_count, {n});
    d["stress"] = from_vector(st.stress, {st.stress.size()});
    d["scalars"] = from_vector(st.scalars, {st.scalars.size()});
    d["counters"] = from_vector(st.counters, {st.counters.size()});
    d["order"] = from_vector(st.order, {n});
    return d;
}

template <typename T>
std::vector<T> vec(nb::handle h, std::size_t size, const char* name) {
    auto a = nb::cast<nb::ndarray<const T, nb::c_contig, nb::device::cpu>>(h);
    require(a.size() == size, std::string("set_state: ") + name + " has the wrong size");
    return std::vector<T>(a.data(), a.data() + size);
}

void set_state(EventDriven& s, nb::dict d) {
    const std::size_t n = static_cast<std::size_t>(s.size());
    EventDriven::State st;
    st.pos = vec<double>(d["pos"], 3 * n, "pos");
    st.vel = vec<double>(d["vel"], 3 * n, "vel");
    st.omega = vec<double>(d["omega"], 3 * n, "omega");
    st.last = vec<double>(d["last"], n, "last");
    st.count = vec<std::int64_t>(d["count"], n, "count");
    st.cell = vec<std::int32_t>(d["cell"], 3 * n, "cell");
    if (d.contains("ev_time")) {  // without them the events are predicted afresh
        st.ev_time = vec<double>(d["ev_time"], n + 1, "ev_time");
        st.ev_partner = vec<std::int32_t>(d["ev_partner"], n + 1, "ev_partner");
        st.ev_count = vec<std::int64_t>(d["ev_count"], n + 1, "ev_count");
        st.co_time = vec<double>(d["co_time"], n, "co_time");
        st.co_partner = vec<std::int32_t>(d["co_partner"], n, "co_partner");
        st.co_count = vec<std::int64_t>(d["co_count"], n, "co_count");
    }
    st.scalars = vec<double>(d["scalars"], 36, "scalars");
    EventDriven::check_stress_bins(st.scalars[33], st.scalars[34], st.scalars[35], "set_state");
    const auto bins = static_cast<std::size_t>(st.scalars[35]);
    st.stress = vec<double>(d["stress"], 9 * bins, "stress");
    st.counters = vec<std::int64_t>(d["counters"], 8, "counters");
    st.order = vec<std::int32_t>(d["order"], n, "order");
    try {
        s.set_state(st);
    } catch (const std::invalid_argument& err) {
        throw nb::value_error(err.what());
    }
}

nb::tuple collide_py(std::vector<double> n, double ri, double rj, double mi, double mj,
                  double inertia_k, double e, double beta, std::vector<double> vi,
                  std::vector<double> vj, std::vector<double> wi, std::vector<double> wj) {
    require(n.size() == 3 && vi.size() == 3 && vj.size() == 3 && wi.size() == 3 &&
                wj.size() == 3,
            "collide_pair: vectors need 3 components (z = 0 in 2D)");
    double J[3];
    collide(n.data(), ri, rj, 1.0 / mi, 1.0 / mj, inertia_k, e, beta, vi.data(), vj.data(), wi.data(),
                 wj.data(), J);
    auto a = from_vector(vi, {3}), b = from_vector(vj, {3}), c = from_vector(wi, {3}),
         d = from_vector(wj, {3}), j = from_vector(std::vector<double>(J, J + 3), {3});
    return nb::make_tuple(a, b, c, d, j);
}

}  // namespace

nb::dict grow_py(InArr pos, InArr vel, InArr diameter, InArr mass, std::vector<double> box,
                 int dim, bool periodic_y, std::vector<double> y_range, double s_start,
                 double s_end, double rate, double relax_time, double chunk, double temperature,
                 std::int64_t max_events) {
    require(dim == 2 || dim == 3, "dim must be 2 or 3");
    require(box.size() == static_cast<std::size_t>(dim), "box needs dim lengths");
    require(y_range.size() == 2, "y_range needs (lo, hi)");
    const std::size_t n = rows(pos, dim, "positions (N, dim)");
    require(rows(vel, dim, "velocities (N, dim)") == n, "velocities: N rows");
    require(rows(diameter, 1, "diameters (N,)") == n, "diameters: N entries");
    require(rows(mass, 1, "masses (N,)") == n, "masses: N entries");
    GrowthParams p;
    p.dim = dim;
    for (int a = 0; a < dim; ++a) p.box[a] = box[a];
    p.periodic_y = periodic_y;
    p.y_lo = y_range[0];
    p.y_hi = y_range[1];
    p.s_start = s_start;
    p.s_end = s_end;
    p.rate = rate;
    p.relax_time = relax_time;
    p.chunk = chunk;
    p.temperature = temperature;
    p.max_events = max_events;
    std::vector<double> x(3 * n, 0.0), v(3 * n, 0.0);
    for (std::size_t i = 0; i < n; ++i)
        for (int a = 0; a < dim; ++a) {
            x[3 * i + a] = pos.data()[i * dim + a];
            v[3 * i + a] = vel.data()[i * dim + a];
        }
    GrowthResult r;
    try {
        nb::gil_scoped_release release;
        r = grow_packing(p, static_cast<std::int64_t>(n), x.data(), v.data(), diameter.data(),
                         mass.data());
    } catch (const std::invalid_argument& err) {
        throw nb::value_error(err.what());
    }
    auto xo = owned<double>({n, static_cast<std::size_t>(dim)});
    auto vo = owned<double>({n, static_cast<std::size_t>(dim)});
    for (std::size_t i = 0; i < n; ++i)
        for (int a = 0; a < dim; ++a) {
            xo.data()[i * dim + a] = x[3 * i + a];
            vo.data()[i * dim + a] = v[3 * i + a];
        }
    nb::dict d;
    d["positions"] = xo;
    d["velocities"] = vo;
    d["reached"] = r.reached;
    d["scale"] = r.scale;
    d["collisions"] = r.collisions;
    d["events"] = r.events;
    d["time"] = r.time;
    d["relax_virial"] = r.relax_virial;
    return d;
}

void bind(nb::module_& m) {
    m.def("edmd_grow_packing", &grow_py, "positions"_a, "velocities"_a, "diameters"_a,
          "masses"_a, "box"_a, "dim"_a, "periodic_y"_a, "y_range"_a, "s_start"_a, "s_end"_a,
          "rate"_a, "relax_time"_a, "chunk"_a, "temperature"_a, "max_events"_a,
          "Lubachevsky-Stillinger growth of the diameters from s_start to s_end times "
          "`diameters` (see demstudy.scene.fluid_start). Returns a dict: positions, "
          "velocities, reached, scale, collisions, events, time, relax_virial.");
    m.def("edmd_set_simd", &set_pair_simd, "enabled"_a,
          "Use the AVX2 pair-time kernel of the event-driven engine when the CPU has it "
          "(default); returns whether it is used. Both give identical bits (for tests).");
    m.def("edmd_collide_pair", &collide_py, "n"_a, "ri"_a, "rj"_a, "mi"_a, "mj"_a, "inertia_k"_a,
          "e"_a, "beta"_a, "vi"_a, "vj"_a, "wi"_a, "wj"_a,
          "One hard-particle collision (n: unit normal from i to j, 3 components; spins as "
          "3-vectors, z only in 2D). Returns (vi', vj', wi', wj', J), J the impulse on i.");
    nb::class_<EventDriven>(m, "EventDriven",
                            "Event-driven hard discs/spheres in a periodic box (see "
                            "demstudy.engines.edmd.core for the documented wrapper).")
        .def("__init__",
             [](EventDriven* self, InArr pos, InArr vel, InArr omega, InArr diameter,
                InArr mass, std::vector<double> box, int dim, double e, double beta,
                double inertia_k, double tc, nb::kwargs options) {
                 EventDriven* made = make(pos, vel, omega, diameter, mass, box, dim, e, beta,
                                          inertia_k, tc, options);
                 new (self) EventDriven(std::move(*made));
                 delete made;
             },
             "positions"_a, "velocities"_a, "angular_velocities"_a, "diameters"_a, "masses"_a,
             "box"_a, "dim"_a, "e"_a = 1.0, "beta"_a = -1.0, "inertia_k"_a = 0.4,
             "tc"_a = 0.0, "options"_a)
        .def("advance_to",
             [](EventDriven& s, double t, std::int64_t max_events, std::int64_t stop_collisions) {
                 bool reached;
                 try {
                     nb::gil_scoped_release release;
                     reached = s.advance_to(t, max_events, stop_collisions);
                 } catch (const std::invalid_argument& err) {
                     throw nb::value_error(err.what());
                 }
                 return reached;
             },
             "t"_a, "max_events"_a = 0, "stop_collisions"_a = 0,
             "Process events up to t, then synchronise every particle to t (returns True). "
             "Stop early (synchronised to the last event time, returns False) after "
             "max_events events (> 0) or when the pair-collision count reaches "
             "stop_collisions (> 0).")
        .def_prop_ro("time", &EventDriven::time)
        .def_prop_ro("n", &EventDriven::size)
        .def_prop_ro("dim", &EventDriven::dim)
        .def("positions",
             [](const EventDriven& s) {
                 auto out = owned<double>({static_cast<std::size_t>(s.size()),
                                           static_cast<std::size_t>(s.dim())});
                 s.positions(out.data());
                 return out;
             })
        .def("velocities",
             [](const EventDriven& s) {
                 auto out = owned<double>({static_cast<std::size_t>(s.size()),
                                           static_cast<std::size_t>(s.dim())});
                 s.velocities(out.data());
                 return out;
             })
        .def("angular_velocities",
             [](const EventDriven& s) {
                 auto out = owned<double>({static_cast<std::size_t>(s.size()),
                                           static_cast<std::size_t>(s.dim() == 2 ? 1 : 3)});
                 s.angular_velocities(out.data());
                 return out;
             })
        .def_prop_ro("kinetic_energy", &EventDriven::kinetic_energy)
        .def_prop_ro("rotational_energy", &EventDriven::rotational_energy)
        .def_prop_ro("collisions", &EventDriven::collisions)
        .def_prop_ro("cell_crossings", &EventDriven::cell_crossings)
        .def_prop_ro("events", &EventDriven::events)
        .def_prop_ro("invalid_events", &EventDriven::invalid_events)
        .def_prop_ro("elastic_tc_collisions", &EventDriven::elastic_tc_collisions)
        .def_prop_ro("virial", &EventDriven::virial)
        .def_prop_ro("virial_tensor",
                     [](const EventDriven& s) {
                         const double* v = s.virial_tensor();
                         return nb::cast(from_vector(std::vector<double>(v, v + 9), {3, 3}), nb::rv_policy::move);
                     })
        .def_prop_ro("dissipated", &EventDriven::dissipated)
        .def_prop_ro("gravity_work", &EventDriven::gravity_work)
        .def_prop_ro("wall_collisions", &EventDriven::wall_collisions)
        .def_prop_ro("resting_bounces", &EventDriven::resting_bounces)
        .def_prop_ro("shear_offset", &EventDriven::shear_offset)
        .def_prop_ro("box",
                     [](const EventDriven& s) {
                         const double* b = s.params().box;
                         return nb::cast(from_vector(std::vector<double>(b, b + s.dim()),
                                            {static_cast<std::size_t>(s.dim())}), nb::rv_policy::move);
                     })
        .def("wall_impulse",
             [](const EventDriven& s, int side) {
                 require(side == 0 || side == 1, "side: 0 (lower) or 1 (upper)");
                 const double* j = s.wall_impulse(side);
                 return from_vector(std::vector<double>(j, j + 3), {3});
             },
             "side"_a, "Cumulative impulse the wall gave the particles (3 components).")
        .def("wall_work",
             [](const EventDriven& s, int side) {
                 require(side == 0 || side == 1, "side: 0 (lower) or 1 (upper)");
                 return s.wall_work(side);
             },
             "side"_a, "Cumulative work done by the wall on the particles.")
        .def("wall_position",
             [](const EventDriven& s, int side) {
                 require(side == 0 || side == 1, "side: 0 (lower) or 1 (upper)");
                 return s.params().wall[side].position(s.time());
             },
             "side"_a)
        .def("set_wall",
             [](EventDriven& s, int side, double y, double vn, double ux, double uz) {
                 try {
                     s.set_wall(side, y, vn, ux, uz);
                 } catch (const std::invalid_argument& err) {
                     throw nb::value_error(err.what());
                 }
             },
             "side"_a, "position"_a, "normal_velocity"_a, "velocity"_a, "velocity_z"_a = 0.0,
             "Move a wall now: position, normal velocity, surface velocity (x, z).")
        .def("set_stress_bins",
             [](EventDriven& s, double lo, double width, std::int64_t n) {
                 try {
                     s.set_stress_bins(lo, width, n);
                 } catch (const std::invalid_argument& err) {
                     throw nb::value_error(err.what());
                 }
             },
             "lo"_a, "width"_a, "n"_a, "New stress bins along y; the sums restart at zero.")
        .def("scale_width",
             [](EventDriven& s, double f) {
                 try {
                     return s.scale_width(f);
                 } catch (const std::invalid_argument& err) {
                     throw nb::value_error(err.what());
                 }
             },
             "factor"_a,
             "Scale x positions and the x period by factor, limited so that no pair overlaps "
             "(a jammed packing keeps its width); returns the factor applied.")
        .def_prop_ro("stress_sums",
                     [](const EventDriven& s) {
                         const auto& v = s.stress_sums();
                         return nb::cast(from_vector(v, {v.size() / 9, 3, 3}), nb::rv_policy::move);
                     })
        .def("take_log",
             [](EventDriven& s) {
                 const auto log = s.take_log();
                 const std::size_t m = log.size();
                 const std::size_t dim = static_cast<std::size_t>(s.dim());
                 nb::dict d;
                 auto col = [&](auto get, std::size_t width) {
                     auto out = owned<double>(width == 1 ? std::vector<std::size_t>{m}
                                                         : std::vector<std::size_t>{m, width});
                     double* o = out.data();
                     for (std::size_t k = 0; k < m; ++k) get(log[k], o + k * width);
                     return out;
                 };
                 d["time"] = col([](const LogRecord& r, double* o) { o[0] = r.time; }, 1);
                 d["kind"] = col([](const LogRecord& r, double* o) { o[0] = r.kind; }, 1);
                 d["i"] = col([](const LogRecord& r, double* o) { o[0] = r.i; }, 1);
                 d["j"] = col([](const LogRecord& r, double* o) { o[0] = r.j; }, 1);
                 d["position"] = col([dim](const LogRecord& r, double* o) {
                     for (std::size_t a = 0; a < dim; ++a) o[a] = r.point[a]; }, dim);
                 d["normal"] = col([dim](const LogRecord& r, double* o) {
                     for (std::size_t a = 0; a < dim; ++a) o[a] = r.normal[a]; }, dim);
                 d["branch"] = col([dim](const LogRecord& r, double* o) {
                     for (std::size_t a = 0; a < dim; ++a) o[a] = r.branch[a]; }, dim);
                 d["impulse"] = col([dim](const LogRecord& r, double* o) {
                     for (std::size_t a = 0; a < dim; ++a) o[a] = r.impulse[a]; }, dim);
                 d["velocity"] = col([dim](const LogRecord& r, double* o) {
                     for (std::size_t a = 0; a < dim; ++a) o[a] = r.velocity[a]; }, dim);
                 d["spin_velocity"] = col([dim](const LogRecord& r, double* o) {
                     for (std::size_t a = 0; a < dim; ++a) o[a] = r.slip[a]; }, dim);
                 return d;
             },
             "Drain the collision log: dict of arrays (time, kind 0 pair / 1 lower wall / 2 "
             "upper wall, i, j (input indices, -1 for walls), position = contact point, "
             "normal (i -> j or wall), branch (r_j - r_i; contact point - r_i for walls), "
             "impulse on i, velocity = v_i - v_j (walls: v_i - u_wall) and spin_velocity = "
             "the contact-point relative velocity, both before the collision).")
        .def("min_wall_gap", &EventDriven::min_wall_gap,
             "Smallest particle-surface-to-wall distance (inf without walls; < 0: inside).")
        .def_prop_ro("cells",
                     [](const EventDriven& s) {
                         const int* c = s.cells_per_axis();
                         return nb::make_tuple(c[0], c[1], c[2]);
                     })
        .def("min_gap", &EventDriven::min_gap,
             "Smallest centre distance minus contact distance over all pairs (< 0: overlap).")
        .def_prop_ro("memory_bytes", &EventDriven::memory_bytes)
        .def("get_state", &state_dict)
        .def("set_state", &set_state, "state"_a);
}

}  // namespace demstudy::edmd
