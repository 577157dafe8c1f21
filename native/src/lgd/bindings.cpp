// nanobind bindings of the LGD step (demstudy._native.lgd_run, lgd_time_step). Call them
// through demstudy.engines.lgd.core, which validates the lattice and the parameters.
// Units: the listing's integers; dimensionless particle units (d = 1, m = 1, g = 1) above.
#include <nanobind/nanobind.h>
#include <nanobind/ndarray.h>
#include <nanobind/stl/string.h>
#include <nanobind/stl/tuple.h>

#include <cstdint>
#include <string>
#include <tuple>

#include "lgd/lgd.hpp"

namespace nb = nanobind;
using namespace nb::literals;

namespace demstudy::lgd {

namespace {

template <typename T>
using Grid = nb::ndarray<T, nb::ndim<2>, nb::c_contig, nb::device::cpu>;

void require(bool ok, const std::string& what) {
    if (!ok) throw nb::value_error(what.c_str());
}

template <typename T>
T field(const nb::dict& d, const char* name) {
    require(d.contains(name), std::string("lgd params: missing '") + name + "'");
    return nb::cast<T>(d[name]);
}

Params parse(const nb::dict& d) {
    Params p{};
#define LGD_INT(f) p.f = field<std::int64_t>(d, #f)
    LGD_INT(idl); LGD_INT(id); LGD_INT(idx); LGD_INT(idy); LGD_INT(id2); LGD_INT(icb);
    LGD_INT(icp); LGD_INT(icw); LGD_INT(iep1); LGD_INT(iep2); LGD_INT(iew1); LGD_INT(iew2);
    LGD_INT(ke); LGD_INT(ke1); LGD_INT(ke2); LGD_INT(kx); LGD_INT(ky); LGD_INT(kq);
    LGD_INT(kxp); LGD_INT(kxw); LGD_INT(kqp); LGD_INT(kqw); LGD_INT(igx); LGD_INT(igy);
    LGD_INT(ntu); LGD_INT(itm); LGD_INT(nw);
#undef LGD_INT
    p.gm = field<double>(d, "gm");
    p.gm2 = field<double>(d, "gm2");
    p.dl3 = field<double>(d, "dl3");
    p.dy1 = field<double>(d, "dy1");
    p.dy3 = field<double>(d, "dy3");
    require(p.kq > 0 && p.kqp > 0 && p.kqw > 0 && p.ke > 0 && p.ke1 > 0 && p.id2 > 0,
            "lgd params: kq, ke and idx must be positive");
    return p;
}

nb::ndarray<nb::numpy, std::int64_t> owned_log(std::size_t n_steps) {
    const std::size_t total = n_steps * kLogFields;
    auto* data = new std::int64_t[total > 0 ? total : 1]();
    nb::capsule owner(data, [](void* q) noexcept { delete[] static_cast<std::int64_t*>(q); });
    const std::size_t shape[2] = {n_steps, static_cast<std::size_t>(kLogFields)};
    return nb::ndarray<nb::numpy, std::int64_t>(data, 2, shape, owner);
}

using Scalars = std::tuple<std::int64_t, std::int64_t, std::int64_t, std::int64_t, std::int64_t>;

std::tuple<nb::ndarray<nb::numpy, std::int64_t>, Scalars> run(
    Grid<std::int8_t> mlp, Grid<std::int64_t> ipx, Grid<std::int64_t> ipy,
    Grid<std::int64_t> ivx, Grid<std::int64_t> ivy, Grid<std::int32_t> nlp,
    const nb::dict& params, Scalars scalars, std::int64_t n_steps) {
    const std::size_t nyt = mlp.shape(0), nxt = mlp.shape(1);
    for (auto [shape0, shape1, name] :
         {std::tuple{ipx.shape(0), ipx.shape(1), "ipx"}, {ipy.shape(0), ipy.shape(1), "ipy"},
          {ivx.shape(0), ivx.shape(1), "ivx"}, {ivy.shape(0), ivy.shape(1), "ivy"},
          {nlp.shape(0), nlp.shape(1), "nlp"}})
        require(shape0 == nyt && shape1 == nxt,
                std::string(name) + " must have the shape of mlp (nyt, nxt)");
    require(nxt >= 6 && nxt % 6 == 0 && nyt >= 4, "lattice must be nyt >= 4 by nxt % 6 == 0");
    require(n_steps >= 0, "n_steps must be >= 0");
    const Params p = parse(params);
    State s{mlp.data(), ipx.data(), ipy.data(), ivx.data(), ivy.data(), nlp.data(),
            static_cast<std::int64_t>(nxt), static_cast<std::int64_t>(nyt),
            std::get<0>(scalars), std::get<1>(scalars), std::get<2>(scalars),
            std::get<3>(scalars), std::get<4>(scalars)};
    auto log = owned_log(static_cast<std::size_t>(n_steps));
    std::int64_t* out = log.data();
    {
        nb::gil_scoped_release release;
        run_steps(p, s, n_steps, out);
    }
    return {log, Scalars{s.pv2, s.pvx, s.pvy, s.nn, s.itt}};
}

}  // namespace

void bind(nb::module_& m) {
    m.def("lgd_run", &run, "mlp"_a.noconvert(), "ipx"_a.noconvert(), "ipy"_a.noconvert(),
          "ivx"_a.noconvert(), "ivy"_a.noconvert(), "nlp"_a.noconvert(), "params"_a,
          "scalars"_a, "n_steps"_a,
          "Gutt's LGD: advance the lattice arrays (mlp int8, ipx/ipy/ivx/ivy int64, nlp int32, "
          "each C-contiguous (nyt, nxt)) in place by n_steps steps. params: the listing's "
          "derived constants (demstudy.engines.lgd.reference.Derived fields) and nw; scalars: "
          "(pv2, pvx, pvy, nn, itt). Returns (log int64 (n_steps, 14) in STEP_LOG_FIELDS "
          "order, the updated scalars).");
    m.def("lgd_time_step",
          [](const nb::dict& params, std::int64_t pv2, std::int64_t pvx, std::int64_t pvy) {
              return time_step(parse(params), pv2, pvx, pvy);
          },
          "params"_a, "pv2"_a, "pvx"_a, "pvy"_a, "The step's it (ticks) from the peak grain.");
}

}  // namespace demstudy::lgd
