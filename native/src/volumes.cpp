// Exact disc-strip / sphere-slab overlaps and the binning kernel (see volumes.hpp).
// Dimensionless particle units: d = 1, m = 1.
#include "volumes.hpp"

#include <algorithm>
#include <cmath>
#include <utility>

// This file is compiled twice: once as the baseline (DEMSTUDY_VARIANT undefined, which also
// defines the public API below) and, on x86-64 with GCC/Clang, once more with -mavx2 -mfma
// and DEMSTUDY_VARIANT=x86_64_v3 (see CMakeLists.txt). The kernels live in a namespace named
// after the variant and the public functions pick one at run time from the CPU features.
// Everything else is internal linkage so the two builds cannot mix code.
#ifndef DEMSTUDY_VARIANT
#define DEMSTUDY_VARIANT baseline
#define DEMSTUDY_PUBLIC_API 1
#endif

namespace demstudy {
namespace DEMSTUDY_VARIANT {
namespace {

constexpr double kPi = 3.14159265358979323846;

// asin(s) for 0 <= s <= 1/2 as s + s R(s^2), with the rational minimax R of fdlibm's e_asin.c
// (Copyright (C) 1993 by Sun Microsystems, Inc. All rights reserved. Developed at SunSoft, a
// Sun Microsystems, Inc. business. Permission to use, copy, modify, and distribute this
// software is freely granted, provided that this notice is preserved.) About 3x faster
// than glibc's correctly rounded asin; error below 1 ulp on this range.
inline double asin_small(double s, double z) noexcept {
    const double p = z * (1.66666666666666657415e-01 +
                     z * (-3.25565818622400915405e-01 +
                     z * (2.01212532134862925881e-01 +
                     z * (-4.00555345006794114027e-02 +
                     z * (7.91534994289814532176e-04 +
                     z * 3.47933107596021167570e-05)))));
    const double q = 1.0 + z * (-2.40339491173441421878e+00 +
                           z * (2.02094576023350569471e+00 +
                           z * (-6.88283971605453293030e-01 +
                           z * 7.70381505559019352791e-02)));
    return s + s * (p / q);
}

// pi/2 + asin(x) for x in [-1, 1], without cancellation near x = -1: for |x| > 1/2 the
// half-angle forms pi/2 + asin(x) = 2 asin(sqrt((1+x)/2)) (x < 0) and pi - 2 asin(sqrt((1-x)/2))
// (x > 0).
inline double half_pi_plus_asin(double x) noexcept {
    const double ax = std::fabs(x);
    if (ax <= 0.5) return 0.5 * kPi + asin_small(x, x * x);
    const double z = 0.5 * (1.0 - ax);
    const double t = 2.0 * asin_small(std::sqrt(z), z);
    return x < 0.0 ? t : kPi - t;
}

// Cumulative disc area / sphere volume below offset s from the centre, for an s known to
// lie (up to rounding) inside the particle: no range branches, only clamping.
template <int Dim>
inline double cumulative_inside(double s, double r) noexcept {
    if constexpr (Dim == 2) {
        const double x = std::min(1.0, std::max(-1.0, s / r));
        return r * r * (half_pi_plus_asin(x) + x * std::sqrt((1.0 - x) * (1.0 + x)));
    } else {
        const double h = std::min(2.0 * r, std::max(0.0, r + s));
        return (kPi / 3.0) * h * h * (3.0 * r - h);
    }
}

template <int Dim>
inline double full_volume(double r) noexcept {
    if constexpr (Dim == 2) return kPi * r * r;
    else return (4.0 / 3.0) * kPi * r * r * r;
}

template <int Dim>
inline double cumulative(double s, double r) noexcept {
    if (s <= -r) return 0.0;
    if (s >= r) return full_volume<Dim>(r);
    return cumulative_inside<Dim>(s, r);
}

// Adds V * vals[0:nv] to row (NV > 0: compile-time width so the loop unrolls/vectorises).
template <int NV>
inline void add_row(double* __restrict row, const double* __restrict vals, double v,
                    std::int64_t nv) noexcept {
    if constexpr (NV >= 0) {
        (void)nv;
        for (int f = 0; f < NV; ++f) row[f] += v * vals[f];
    } else {
        for (std::int64_t f = 0; f < nv; ++f) row[f] += v * vals[f];
    }
}

// One particle (or periodic image) centred at c against bins [lo + b w, lo + (b+1) w).
// Bin k collects C(e_{k+1}) - C(e_k), C the cumulative volume below edge e; edges strictly
// inside the particle go through cumulative_inside, the outer ones are 0 / full volume
// unless the grid ends cut the particle (then the part beyond the grid is dropped).
template <int Dim, int NV>
inline void deposit(double c, double r, const double* __restrict vals, std::int64_t nv,
                    double lo, double width, double inv_width, std::int64_t nbins,
                    double* __restrict vol, double* __restrict sums) noexcept {
    const double a = (c - r - lo) * inv_width;  // particle extent in bin units
    const double b = (c + r - lo) * inv_width;
    const double nb = static_cast<double>(nbins);
    if (!(b > 0.0) || !(a < nb)) return;
    const bool cut_lo = a < 0.0;
    const bool cut_hi = b > nb;
    const std::int64_t kb = cut_lo ? 0 : static_cast<std::int64_t>(a);
    std::int64_t ke = cut_hi ? nbins - 1 : static_cast<std::int64_t>(b);
    if (ke > kb && static_cast<double>(ke) == b) --ke;  // touches bin ke only at its lower edge
    double prev = cut_lo ? cumulative<Dim>(lo - c, r) : 0.0;
    for (std::int64_t k = kb; k < ke; ++k) {
        // max(): keeps round-off from producing tiny negative overlaps
        const double cur =
            std::max(prev, cumulative_inside<Dim>(lo + static_cast<double>(k + 1) * width - c, r));
        const double v = cur - prev;
        prev = cur;
        vol[k] += v;
        add_row<NV>(sums + k * nv, vals, v, nv);
    }
    const double last = cut_hi ? cumulative<Dim>(lo + nb * width - c, r) : full_volume<Dim>(r);
    const double v = std::max(0.0, last - prev);
    vol[ke] += v;
    add_row<NV>(sums + ke * nv, vals, v, nv);
}

// The bin grid lo + b * width, b = 0..nbins, optionally periodic with period > 0.
struct Grid {
    double lo, width, inv_width, end, period, inv_period;
    std::int64_t nbins;
    bool one_period;  // the bins lie within one period

    Grid(double lo_, double width_, std::int64_t nbins_, double period_) noexcept
        : lo(lo_), width(width_), inv_width(1.0 / width_),
          end(lo_ + static_cast<double>(nbins_) * width_), period(period_),
          inv_period(period_ > 0.0 ? 1.0 / period_ : 0.0), nbins(nbins_),
          one_period(end <= lo_ + period_ * (1.0 + 1e-9)) {}
};

// One particle with all its periodic images (period > 0) or just itself (period == 0).
template <int Dim, int NV>
inline void deposit_particle(double c, double r, const double* __restrict vals, std::int64_t nv,
                             const Grid& g, double* __restrict vol,
                             double* __restrict sums) noexcept {
    if (g.period <= 0.0) {
        deposit<Dim, NV>(c, r, vals, nv, g.lo, g.width, g.inv_width, g.nbins, vol, sums);
        return;
    }
    const double p = g.period;
    double c0 = c;  // wrapped into [lo, lo + P)
    if (c0 < g.lo || c0 >= g.lo + p) {
        c0 = c - p * std::floor((c - g.lo) * g.inv_period);
        if (c0 >= g.lo + p) c0 -= p;
        if (c0 < g.lo) c0 = g.lo;
    }
    deposit<Dim, NV>(c0, r, vals, nv, g.lo, g.width, g.inv_width, g.nbins, vol, sums);
    if (2.0 * r <= p && g.one_period) {  // at most one other image reaches the bins
        if (c0 - r < g.lo)
            deposit<Dim, NV>(c0 + p, r, vals, nv, g.lo, g.width, g.inv_width, g.nbins, vol, sums);
        else if (c0 + r > g.lo + p)
            deposit<Dim, NV>(c0 - p, r, vals, nv, g.lo, g.width, g.inv_width, g.nbins, vol, sums);
        return;
    }
    // Particles wider than half the period, or bins beyond one period: every other image
    // c0 + k P that reaches into [lo, end].
    const auto kmin = static_cast<std::int64_t>(-std::ceil(r * g.inv_period));
    const auto kmax = static_cast<std::int64_t>(std::ceil((g.end + r - c0) * g.inv_period));
    for (std::int64_t k = kmin; k <= kmax; ++k)
        if (k != 0)
            deposit<Dim, NV>(c0 + static_cast<double>(k) * p, r, vals, nv, g.lo, g.width,
                             g.inv_width, g.nbins, vol, sums);
}

inline bool bad_particle(double c, double r) noexcept {
    return !std::isfinite(c) || !std::isfinite(r) || r < 0.0;
}

template <int Dim, int NV>
std::int64_t kernel(const double* coord, const double* radius, const double* values,
                    std::int64_t n, std::int64_t nv, double lo, double width, std::int64_t nbins,
                    double period, double* vol, double* sums) noexcept {
    const Grid g(lo, width, nbins, period);
    std::int64_t skipped = 0;
    for (std::int64_t i = 0; i < n; ++i) {
        if (bad_particle(coord[i], radius[i])) {
            ++skipped;
            continue;
        }
        deposit_particle<Dim, NV>(coord[i], radius[i], values + i * nv, nv, g, vol, sums);
    }
    return skipped;
}

// Fused profile kernel: builds the value row of each particle on the stack (layout in
// volumes.hpp) and deposits it, avoiding an (N, F) temporary.
template <int Dim>
std::int64_t profile_kernel(const double* coord, const double* radius, const double* velocity,
                            const double* omega, std::int64_t n, double k_inertia, double lo,
                            double width, std::int64_t nbins, double period, double* vol,
                            double* sums) noexcept {
    constexpr int NR = Dim == 2 ? 1 : 3;
    constexpr int NV = Dim + Dim * (Dim + 1) / 2 + 2 * NR + 3;
    const Grid g(lo, width, nbins, period);
    std::int64_t skipped = 0;
    double row[NV];
    for (std::int64_t i = 0; i < n; ++i) {
        const double c = coord[i];
        const double r = radius[i];
        if (bad_particle(c, r)) {
            ++skipped;
            continue;
        }
        const double* v = velocity + i * Dim;
        const double* w = omega + i * NR;
        int col = 0;
        for (int a = 0; a < Dim; ++a) row[col++] = v[a];
        for (int a = 0; a < Dim; ++a)
            for (int b = a; b < Dim; ++b) row[col++] = v[a] * v[b];
        const double j = k_inertia * r * r;
        double jww = 0.0;
        for (int a = 0; a < NR; ++a) row[col++] = w[a];
        for (int a = 0; a < NR; ++a) {
            row[col++] = j * w[a];
            jww += w[a] * w[a];
        }
        row[col++] = j * jww;
        row[col++] = j;
        row[col] = r > 0.0 ? 1.0 / full_volume<Dim>(r) : 0.0;
        deposit_particle<Dim, NV>(c, r, row, NV, g, vol, sums);
    }
    return skipped;
}

using KernelFn = std::int64_t (*)(const double*, const double*, const double*, std::int64_t,
                                  std::int64_t, double, double, std::int64_t, double, double*,
                                  double*) noexcept;

constexpr int kMaxStatic = 24;

template <int Dim, int... NVs>
constexpr auto make_table(std::integer_sequence<int, NVs...>) {
    struct Table {
        KernelFn fn[sizeof...(NVs)];
    };
    return Table{{&kernel<Dim, NVs>...}};
}

template <int Dim>
KernelFn pick(std::int64_t nv) {
    static constexpr auto table = make_table<Dim>(std::make_integer_sequence<int, kMaxStatic + 1>{});
    if (nv >= 0 && nv <= kMaxStatic) return table.fn[nv];
    return &kernel<Dim, -1>;
}

}  // namespace

std::int64_t accumulate_bins_impl(const double* coord, const double* radius,
                                  const double* values, std::int64_t n, std::int64_t nvalues,
                                  double lo, double width, std::int64_t nbins, int dim,
                                  double period, double* out_volume, double* out_sums) noexcept {
    const KernelFn fn = dim == 2 ? pick<2>(nvalues) : pick<3>(nvalues);
    return fn(coord, radius, values, n, nvalues, lo, width, nbins, period, out_volume, out_sums);
}

std::int64_t accumulate_profile_impl(const double* coord, const double* radius,
                                     const double* velocity, const double* omega, std::int64_t n,
                                     double inertia_factor, double lo, double width,
                                     std::int64_t nbins, int dim, double period,
                                     double* out_volume, double* out_sums) noexcept {
    auto fn = dim == 2 ? &profile_kernel<2> : &profile_kernel<3>;
    return fn(coord, radius, velocity, omega, n, inertia_factor, lo, width, nbins, period,
              out_volume, out_sums);
}

}  // namespace DEMSTUDY_VARIANT

#ifdef DEMSTUDY_PUBLIC_API

#ifdef DEMSTUDY_HAVE_X86_64_V3
namespace x86_64_v3 {
std::int64_t accumulate_bins_impl(const double*, const double*, const double*, std::int64_t,
                                  std::int64_t, double, double, std::int64_t, int, double,
                                  double*, double*) noexcept;
std::int64_t accumulate_profile_impl(const double*, const double*, const double*, const double*,
                                     std::int64_t, double, double, double, std::int64_t, int,
                                     double, double*, double*) noexcept;
}  // namespace x86_64_v3
#endif

namespace {

bool cpu_has_x86_64_v3() noexcept {
#ifdef DEMSTUDY_HAVE_X86_64_V3
    return __builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma");
#else
    return false;
#endif
}

bool g_use_simd = cpu_has_x86_64_v3();

}  // namespace

const char* simd_variant() noexcept { return g_use_simd ? "x86-64-v3" : "baseline"; }

const char* set_simd(bool enabled) noexcept {
    g_use_simd = enabled && cpu_has_x86_64_v3();
    return simd_variant();
}

int profile_nvalues(int dim) noexcept {
    const int nr = dim == 2 ? 1 : 3;
    return dim + dim * (dim + 1) / 2 + 2 * nr + 3;
}

std::int64_t accumulate_profile(const double* coord, const double* radius,
                                const double* velocity, const double* omega, std::int64_t n,
                                double inertia_factor, double lo, double width,
                                std::int64_t nbins, int dim, double period, double* out_volume,
                                double* out_sums) noexcept {
    if (n <= 0 || nbins <= 0 || !(width > 0.0)) return 0;
#ifdef DEMSTUDY_HAVE_X86_64_V3
    if (g_use_simd)
        return x86_64_v3::accumulate_profile_impl(coord, radius, velocity, omega, n,
                                                  inertia_factor, lo, width, nbins, dim, period,
                                                  out_volume, out_sums);
#endif
    return baseline::accumulate_profile_impl(coord, radius, velocity, omega, n, inertia_factor,
                                             lo, width, nbins, dim, period, out_volume, out_sums);
}

double disc_cumulative_area(double s, double r) noexcept { return baseline::cumulative<2>(s, r); }

double sphere_cumulative_volume(double s, double r) noexcept {
    return baseline::cumulative<3>(s, r);
}

double disc_strip_area(double c, double r, double lo, double hi) noexcept {
    if (!(hi > lo)) return 0.0;
    return baseline::cumulative<2>(hi - c, r) - baseline::cumulative<2>(lo - c, r);
}

double sphere_slab_volume(double c, double r, double lo, double hi) noexcept {
    if (!(hi > lo)) return 0.0;
    return baseline::cumulative<3>(hi - c, r) - baseline::cumulative<3>(lo - c, r);
}

void strip_overlaps(const double* coord, const double* radius, std::int64_t n, double lo,
                    double hi, int dim, double* out) noexcept {
    for (std::int64_t i = 0; i < n; ++i)
        out[i] = dim == 2 ? disc_strip_area(coord[i], radius[i], lo, hi)
                          : sphere_slab_volume(coord[i], radius[i], lo, hi);
}

std::int64_t accumulate_bins(const double* coord, const double* radius, const double* values,
                             std::int64_t n, std::int64_t nvalues, double lo, double width,
                             std::int64_t nbins, int dim, double period, double* out_volume,
                             double* out_sums) noexcept {
    if (n <= 0 || nbins <= 0 || !(width > 0.0)) return 0;
#ifdef DEMSTUDY_HAVE_X86_64_V3
    if (g_use_simd)
        return x86_64_v3::accumulate_bins_impl(coord, radius, values, n, nvalues, lo, width,
                                               nbins, dim, period, out_volume, out_sums);
#endif
    return baseline::accumulate_bins_impl(coord, radius, values, n, nvalues, lo, width, nbins,
                                          dim, period, out_volume, out_sums);
}

#endif  // DEMSTUDY_PUBLIC_API

}  // namespace demstudy
