// nanobind bindings of the event-driven engine core (demstudy._native.EventDriven).
// Dimensionless particle units: d = 1, m = 1.
#include <nanobind/nanobind.h>
#include <nanobind/ndarray.h>
#include <nanobind/stl/string.h>
#include <nanobind/stl/vector.h>

#include <cstdint>
#include <cstring>
#include <string>
#include <vector>

#include "edmd/edmd.hpp"

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

EventDriven* make(InArr pos, InArr vel, InArr omega, InArr diameter, InArr mass,
                  std::vector<double> box, int dim, double e, double beta, double inertia_k,
                  double tc) {
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
        require(box[a] > 0.0, "box lengths must be positive");
        p.box[a] = box[a];
    }
    p.restitution = e;
    p.beta = beta;
    p.inertia_k = inertia_k;
    p.tc = tc;
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
    d["ev_time"] = from_vector(st.ev_time, {n});
    d["ev_partner"] = from_vector(st.ev_partner, {n});
    d["ev_count"] = from_vector(st.ev_count, {n});
    d["co_time"] = from_vector(st.co_time, {n});
    d["co_partner"] = from_vector(st.co_partner, {n});
    d["co_count"] = from_vector(st.co_count, {n});
    d["virial"] = from_vector(std::vector<double>(st.virial, st.virial + 9), {3, 3});
    d["time"] = st.time;
    d["dissipated"] = st.dissipated;
    d["collisions"] = st.collisions;
    d["crossings"] = st.crossings;
    d["invalid"] = st.invalid;
    d["tc_elastic"] = st.tc_elastic;
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
        st.ev_time = vec<double>(d["ev_time"], n, "ev_time");
        st.ev_partner = vec<std::int32_t>(d["ev_partner"], n, "ev_partner");
        st.ev_count = vec<std::int64_t>(d["ev_count"], n, "ev_count");
        st.co_time = vec<double>(d["co_time"], n, "co_time");
        st.co_partner = vec<std::int32_t>(d["co_partner"], n, "co_partner");
        st.co_count = vec<std::int64_t>(d["co_count"], n, "co_count");
    }
    auto vir = vec<double>(d["virial"], 9, "virial");
    std::copy(vir.begin(), vir.end(), st.virial);
    st.time = nb::cast<double>(d["time"]);
    st.dissipated = nb::cast<double>(d["dissipated"]);
    st.collisions = nb::cast<std::int64_t>(d["collisions"]);
    st.crossings = nb::cast<std::int64_t>(d["crossings"]);
    st.invalid = nb::cast<std::int64_t>(d["invalid"]);
    st.tc_elastic = nb::cast<std::int64_t>(d["tc_elastic"]);
    try {
        s.set_state(st);
    } catch (const std::invalid_argument& err) {
        throw nb::value_error(err.what());
    }
}

nb::tuple collide(std::vector<double> n, double ri, double rj, double mi, double mj,
                  double inertia_k, double e, double beta, std::vector<double> vi,
                  std::vector<double> vj, std::vector<double> wi, std::vector<double> wj) {
    require(n.size() == 3 && vi.size() == 3 && vj.size() == 3 && wi.size() == 3 &&
                wj.size() == 3,
            "collide_pair: vectors need 3 components (z = 0 in 2D)");
    double J[3];
    collide_pair(n.data(), ri, rj, mi, mj, inertia_k, e, beta, vi.data(), vj.data(), wi.data(),
                 wj.data(), J);
    auto a = from_vector(vi, {3}), b = from_vector(vj, {3}), c = from_vector(wi, {3}),
         d = from_vector(wj, {3}), j = from_vector(std::vector<double>(J, J + 3), {3});
    return nb::make_tuple(a, b, c, d, j);
}

}  // namespace

void bind(nb::module_& m) {
    m.def("edmd_collide_pair", &collide, "n"_a, "ri"_a, "rj"_a, "mi"_a, "mj"_a, "inertia_k"_a,
          "e"_a, "beta"_a, "vi"_a, "vj"_a, "wi"_a, "wj"_a,
          "One hard-particle collision (n: unit normal from i to j, 3 components; spins as "
          "3-vectors, z only in 2D). Returns (vi', vj', wi', wj', J), J the impulse on i.");
    nb::class_<EventDriven>(m, "EventDriven",
                            "Event-driven hard discs/spheres in a periodic box (see "
                            "demstudy.engines.edmd.core for the documented wrapper).")
        .def("__init__",
             [](EventDriven* self, InArr pos, InArr vel, InArr omega, InArr diameter,
                InArr mass, std::vector<double> box, int dim, double e, double beta,
                double inertia_k, double tc) {
                 EventDriven* made = make(pos, vel, omega, diameter, mass, box, dim, e, beta,
                                          inertia_k, tc);
                 new (self) EventDriven(std::move(*made));
                 delete made;
             },
             "positions"_a, "velocities"_a, "angular_velocities"_a, "diameters"_a, "masses"_a,
             "box"_a, "dim"_a, "e"_a = 1.0, "beta"_a = -1.0, "inertia_k"_a = 0.4,
             "tc"_a = 0.0)
        .def("advance_to",
             [](EventDriven& s, double t, std::int64_t max_events) {
                 bool reached;
                 try {
                     nb::gil_scoped_release release;
                     reached = s.advance_to(t, max_events);
                 } catch (const std::invalid_argument& err) {
                     throw nb::value_error(err.what());
                 }
                 return reached;
             },
             "t"_a, "max_events"_a = 0,
             "Process events up to t, then synchronise every particle to t (returns True). "
             "With max_events > 0, stop after that many events if t is not reached, "
             "synchronise to the last event time and return False.")
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
                         return from_vector(std::vector<double>(v, v + 9), {3, 3});
                     })
        .def_prop_ro("dissipated", &EventDriven::dissipated)
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
