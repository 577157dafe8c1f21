// nanobind bindings: demstudy._native (exact overlap volumes and the binning kernel).
// Dimensionless particle units: d = 1, m = 1. Use the typed wrappers in
// demstudy.analysis.volumes rather than calling this module directly.
#include <nanobind/nanobind.h>
#include <nanobind/ndarray.h>

#include <cstdint>
#include <string>

#include "volumes.hpp"

namespace demstudy::edmd {
void bind(nanobind::module_& m);
}
namespace demstudy::lgd {
void bind(nanobind::module_& m);
}

namespace nb = nanobind;
using namespace nb::literals;

using In1 = nb::ndarray<const double, nb::ndim<1>, nb::c_contig, nb::device::cpu>;
using In2 = nb::ndarray<const double, nb::ndim<2>, nb::c_contig, nb::device::cpu>;
using Out1 = nb::ndarray<double, nb::ndim<1>, nb::c_contig, nb::device::cpu>;
using Out2 = nb::ndarray<double, nb::ndim<2>, nb::c_contig, nb::device::cpu>;

namespace {

void check_dim(int dim) {
    if (dim != 2 && dim != 3) throw nb::value_error("dim must be 2 (discs) or 3 (spheres)");
}

void check(bool ok, const std::string& what) {
    if (!ok) throw nb::value_error(what.c_str());
}

// The bin grid and the output arrays, shared by both accumulators.
void check_grid(std::int64_t nbins, double width, double period, const Out1& out_volume,
                const Out2& out_sums, std::int64_t nv) {
    check(nbins > 0, "nbins must be positive");
    check(width > 0.0, "width must be positive");
    check(period >= 0.0, "period must be >= 0 (0 = not periodic)");
    check(static_cast<std::int64_t>(out_volume.shape(0)) == nbins,
          "out_volume must have shape (nbins,)");
    check(static_cast<std::int64_t>(out_sums.shape(0)) == nbins &&
              static_cast<std::int64_t>(out_sums.shape(1)) == nv,
          "out_sums must have shape (nbins, number of values)");
}

std::int64_t accumulate(In1 coord, In1 radius, In2 values, double lo, double width,
                        std::int64_t nbins, int dim, double period, Out1 out_volume,
                        Out2 out_sums) {
    check_dim(dim);
    const std::int64_t n = static_cast<std::int64_t>(coord.shape(0));
    const std::int64_t nv = static_cast<std::int64_t>(values.shape(1));
    check(static_cast<std::int64_t>(radius.shape(0)) == n, "radius must have shape (N,)");
    check(static_cast<std::int64_t>(values.shape(0)) == n, "values must have shape (N, F)");
    check_grid(nbins, width, period, out_volume, out_sums, nv);
    const double* c = coord.data();
    const double* r = radius.data();
    const double* v = values.data();
    double* ov = out_volume.data();
    double* os = out_sums.data();
    nb::gil_scoped_release release;
    return demstudy::accumulate_bins(c, r, v, n, nv, lo, width, nbins, dim, period, ov, os);
}

std::int64_t profile(In1 coord, In1 radius, In2 velocity, In2 omega, double inertia_factor,
                     double lo, double width, std::int64_t nbins, int dim, double period,
                     Out1 out_volume, Out2 out_sums) {
    check_dim(dim);
    const std::int64_t n = static_cast<std::int64_t>(coord.shape(0));
    const std::int64_t nrot = dim == 2 ? 1 : 3;
    const std::int64_t nv = demstudy::profile_nvalues(dim);
    check(static_cast<std::int64_t>(radius.shape(0)) == n, "radius must have shape (N,)");
    check(static_cast<std::int64_t>(velocity.shape(0)) == n &&
              static_cast<std::int64_t>(velocity.shape(1)) == dim,
          "velocity must have shape (N, dim)");
    check(static_cast<std::int64_t>(omega.shape(0)) == n &&
              static_cast<std::int64_t>(omega.shape(1)) == nrot,
          "angular velocity must have shape (N, 1) in 2D or (N, 3) in 3D");
    check_grid(nbins, width, period, out_volume, out_sums, nv);
    const double* c = coord.data();
    const double* r = radius.data();
    const double* v = velocity.data();
    const double* w = omega.data();
    double* ov = out_volume.data();
    double* os = out_sums.data();
    nb::gil_scoped_release release;
    return demstudy::accumulate_profile(c, r, v, w, n, inertia_factor, lo, width, nbins, dim,
                                        period, ov, os);
}

void overlaps(In1 coord, In1 radius, double lo, double hi, int dim, Out1 out) {
    check_dim(dim);
    const std::int64_t n = static_cast<std::int64_t>(coord.shape(0));
    check(static_cast<std::int64_t>(radius.shape(0)) == n, "radius must have shape (N,)");
    check(static_cast<std::int64_t>(out.shape(0)) == n, "out must have shape (N,)");
    const double* c = coord.data();
    const double* r = radius.data();
    double* o = out.data();
    nb::gil_scoped_release release;
    demstudy::strip_overlaps(c, r, n, lo, hi, dim, o);
}

}  // namespace

NB_MODULE(_native, m) {
    demstudy::edmd::bind(m);  // event-driven hard particles (native/src/edmd)
    demstudy::lgd::bind(m);   // Gutt's lattice grain dynamics (native/src/lgd)
    m.doc() = "Exact disc/sphere overlap volumes with strips/slabs and the volume-weighted "
              "binning kernel (dimensionless particle units: d = 1, m = 1).";
    m.def("disc_strip_area", &demstudy::disc_strip_area, "c"_a, "r"_a, "lo"_a, "hi"_a,
          "Area of the disc (centre c along the axis, radius r) inside lo <= y <= hi.");
    m.def("sphere_slab_volume", &demstudy::sphere_slab_volume, "c"_a, "r"_a, "lo"_a, "hi"_a,
          "Volume of the sphere (centre c along the axis, radius r) inside lo <= y <= hi.");
    m.def("strip_overlaps", &overlaps, "coord"_a.noconvert(), "radius"_a.noconvert(), "lo"_a,
          "hi"_a, "dim"_a, "out"_a.noconvert(),
          "out[i] = overlap of particle i with the strip/slab [lo, hi].");
    m.def("accumulate_bins", &accumulate, "coord"_a.noconvert(), "radius"_a.noconvert(),
          "values"_a.noconvert(), "lo"_a, "width"_a, "nbins"_a, "dim"_a, "period"_a,
          "out_volume"_a.noconvert(), "out_sums"_a.noconvert(),
          "Add exact overlaps V_ib to out_volume[b] and V_ib*values[i] to out_sums[b]; "
          "returns the number of particles skipped for a non-finite coordinate/radius.");
    m.def("simd_variant", &demstudy::simd_variant,
          "Kernel instruction set in use: 'x86-64-v3' (AVX2 + FMA) or 'baseline'.");
    m.def("set_simd", &demstudy::set_simd, "enabled"_a,
          "Allow or forbid the AVX2/FMA kernels (for testing); returns the variant in use. "
          "Not thread-safe with concurrently running kernels.");
    m.def("profile_nvalues", &demstudy::profile_nvalues, "dim"_a,
          "Number of value columns of accumulate_profile: 10 in 2D, 18 in 3D.");
    m.def("accumulate_profile", &profile, "coord"_a.noconvert(), "radius"_a.noconvert(),
          "velocity"_a.noconvert(), "omega"_a.noconvert(), "inertia_factor"_a, "lo"_a,
          "width"_a, "nbins"_a, "dim"_a, "period"_a, "out_volume"_a.noconvert(),
          "out_sums"_a.noconvert(),
          "accumulate_bins with the value row built per particle: v_a | v_a v_b (a <= b) | "
          "w_a | j w_a | j |w|^2 | j | 1/V, where j = inertia_factor * r^2 = I/m, V = particle "
          "volume.");
}
