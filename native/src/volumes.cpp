// Exact disc-strip / sphere-slab overlaps and the binning kernel (see volumes.hpp).
// Dimensionless particle units: d = 1, m = 1.
#include "volumes.hpp"

#include <algorithm>
#include <cmath>
#include <utility>

#if defined(__AVX2__) && defined(__FMA__)
#include <immintrin.h>
#endif

// Inlining hints for the per-particle hot path, whose helpers GCC otherwise leaves as calls.
#if defined(__GNUC__)
#define DEMSTUDY_ALWAYS_INLINE inline __attribute__((always_inline))
#define DEMSTUDY_NOINLINE __attribute__((noinline))
#else
#define DEMSTUDY_ALWAYS_INLINE inline
#define DEMSTUDY_NOINLINE
#endif

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


// Disc area below the chord at offset s from the centre of a disc of radius r is r^2 F(x),
// x = s/r, F(x) = pi/2 + asin(x) + x sqrt(1 - x^2), evaluated without asin and on two ranges
// (each a polynomial: no branch is needed to pick between them when both are computed):
//  * |x| <= 1/2: F = pi/2 + x P(x^2), with P(u) = 2 - u/3 - u^2/20 - ... (asin(x) + x sqrt(1-x^2)
//    is odd and smooth for |x| < 1).
//  * |x| > 1/2: the cap of height y = 1 - |x| = (r - |s|)/r (exact difference) beyond the chord,
//    G(y) = acos(1-y) - (1-y) sqrt(2y - y^2) = y^(3/2) H(y), H smooth; F = G (x < 0) or pi - G.
//    Unlike the textbook form this has no cancellation for thin caps: the relative error stays
//    at a few ulp as y -> 0.
// P and H are near-minimax (Chebyshev) fits computed with mpmath (60 digits) and rounded to
// double: relative approximation error 0.09 ulp (P, u in [0, 1/4]) and 0.06 ulp (H, y in
// [0, 1/2]). Check values: P(0) = 2, P'(0) = -1/3; H(0) = 4 sqrt(2)/3, H'(0) = -sqrt(2)/5.
constexpr double kPiLo = 1.2246467991473532e-16;  // pi - kPi
constexpr int kPDegree = 11;
constexpr double kP[kPDegree + 1] = {
    2.0,                    -0.3333333333333511,   -0.04999999999663193,
    -0.017857143106917415,  -0.008680546021522937, -0.00497180464567741,
    -0.0031520287203522872, -0.002176278596694781, -0.0013711844439742535,
    -0.0018117577886640646, 0.0006975413057050447, -0.0026317556400044352,
};
constexpr int kHDegree = 12;
constexpr double kH[kHDegree + 1] = {
    1.8856180831641267,     -0.2828427124746174,    -0.025253813613985845,
    -0.004910463750341154,  -0.0012555164807623337, -0.00037182357851614484,
    -0.00012086405958858275, -4.177127713410263e-05, -1.568205207592542e-05,
    -4.544728648768665e-06, -4.293077568069963e-06, 1.3131152867583043e-06,
    -1.5656378353065027e-06,
};

template <int Degree>
inline double horner(const double (&c)[Degree + 1], double t) noexcept {
    double p = c[Degree];
    for (int k = Degree - 1; k >= 0; --k) p = p * t + c[k];
    return p;
}

// r^2 F(s/r) for |s| <= r up to rounding; offsets just outside the disc give exactly 0 / pi r^2.
inline double disc_cumulative_inside(double s, double r) noexcept {
    const double x = s / r;
    if (std::fabs(x) <= 0.5)
        return r * r * ((0.5 * kPiLo + x * horner<kPDegree>(kP, x * x)) + 0.5 * kPi);
    // clamped (also maps a NaN from 0/0 to 0; then r = 0 and the result is 0 anyway)
    const double y = std::min(1.0, std::max(0.0, (r - std::fabs(s)) / r));
    const double g = y * std::sqrt(y) * horner<kHDegree>(kH, y);
    return r * r * (std::signbit(s) ? g : (kPiLo - g) + kPi);
}

#if defined(__AVX2__) && defined(__FMA__)
// out[i] = disc_cumulative_inside(s[i], r[i]) for i < n, four at a time: both ranges are
// computed and blended. n is rounded up to a multiple of 4: the arrays must be padded with
// valid values.
inline void disc_cumulative_batch(const double* s, const double* r, double* out,
                                  int n) noexcept {
    const __m256d zero = _mm256_setzero_pd(), one = _mm256_set1_pd(1.0);
    const __m256d half = _mm256_set1_pd(0.5), sign = _mm256_set1_pd(-0.0);
    const __m256d pi = _mm256_set1_pd(kPi), pi_lo = _mm256_set1_pd(kPiLo);
    const __m256d half_pi = _mm256_set1_pd(0.5 * kPi), half_pi_lo = _mm256_set1_pd(0.5 * kPiLo);
    for (int i = 0; i < n; i += 4) {
        const __m256d vs = _mm256_load_pd(s + i);
        const __m256d vr = _mm256_load_pd(r + i);
        const __m256d as = _mm256_andnot_pd(sign, vs);
        // |x| <= 1/2
        const __m256d x = _mm256_div_pd(vs, vr);
        const __m256d u = _mm256_mul_pd(x, x);
        __m256d p = _mm256_set1_pd(kP[kPDegree]);
        for (int k = kPDegree - 1; k >= 0; --k)
            p = _mm256_fmadd_pd(p, u, _mm256_set1_pd(kP[k]));
        const __m256d f_mid = _mm256_add_pd(_mm256_fmadd_pd(x, p, half_pi_lo), half_pi);
        // |x| > 1/2 (min/max return their second operand for a NaN: max(NaN, 0) = 0)
        const __m256d y =
            _mm256_min_pd(_mm256_max_pd(_mm256_div_pd(_mm256_sub_pd(vr, as), vr), zero), one);
        __m256d h = _mm256_set1_pd(kH[kHDegree]);
        for (int k = kHDegree - 1; k >= 0; --k)
            h = _mm256_fmadd_pd(h, y, _mm256_set1_pd(kH[k]));
        const __m256d g = _mm256_mul_pd(_mm256_mul_pd(y, _mm256_sqrt_pd(y)), h);
        const __m256d upper = _mm256_add_pd(_mm256_sub_pd(pi_lo, g), pi);
        const __m256d f_cap = _mm256_blendv_pd(upper, g, vs);  // sign bit of s set: g
        const __m256d mid = _mm256_cmp_pd(_mm256_andnot_pd(sign, x), half, _CMP_LE_OQ);
        const __m256d f = _mm256_blendv_pd(f_cap, f_mid, mid);
        _mm256_store_pd(out + i, _mm256_mul_pd(_mm256_mul_pd(vr, vr), f));
    }
}
#else
inline void disc_cumulative_batch(const double* s, const double* r, double* out,
                                  int n) noexcept {
    for (int i = 0; i < n; ++i) out[i] = disc_cumulative_inside(s[i], r[i]);
}
#endif

// Cumulative disc area / sphere volume below offset s from the centre, for an s known to
// lie (up to rounding) inside the particle: no range branches, only clamping.
template <int Dim>
inline double cumulative_inside(double s, double r) noexcept {
    if constexpr (Dim == 2) {
        return disc_cumulative_inside(s, r);
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

// add_row for value rows written well before (the batched 2D path): in groups of four with
// all loads before the stores, which GCC turns into full-width vector code without a run-time
// aliasing check. (For a row written just before, as in the 3D path, the scalar code that
// GCC picks for add_row is faster: wide loads cannot forward from narrow recent stores.)
template <int NV>
inline void add_row_wide(double* __restrict row, const double* __restrict vals, double v,
                         std::int64_t nv) noexcept {
    if constexpr (NV >= 0) {
        (void)nv;
        int f = 0;
        for (; f + 4 <= NV; f += 4) {
            double sum[4];
            for (int q = 0; q < 4; ++q) sum[q] = row[f + q] + v * vals[f + q];
            for (int q = 0; q < 4; ++q) row[f + q] = sum[q];
        }
        for (; f < NV; ++f) row[f] += v * vals[f];
    } else {
        for (std::int64_t f = 0; f < nv; ++f) row[f] += v * vals[f];
    }
}

// The bins a particle (or periodic image) centred at c overlaps, [kb, ke], and the
// cumulative volumes at its two ends: `first` below lo + kb w (0 unless the grid start cuts the
// particle) and `last` below lo + (ke+1) w (the full volume unless the grid end cuts it).
// The edges lo + (k+1) w, kb <= k < ke, lie strictly inside the particle.
struct Span {
    std::int64_t kb, ke;
    double first, last;
};

template <int Dim>
DEMSTUDY_ALWAYS_INLINE bool find_span(double c, double r, double lo, double width, double inv_width,
                      std::int64_t nbins, Span& sp) noexcept {
    const double a = (c - r - lo) * inv_width;  // particle extent in bin units
    const double b = (c + r - lo) * inv_width;
    const double nb = static_cast<double>(nbins);
    if (!(b > 0.0) || !(a < nb)) return false;
    const bool cut_lo = a < 0.0;
    const bool cut_hi = b > nb;
    sp.kb = cut_lo ? 0 : static_cast<std::int64_t>(a);
    sp.ke = cut_hi ? nbins - 1 : static_cast<std::int64_t>(b);
    if (sp.ke > sp.kb && static_cast<double>(sp.ke) == b) --sp.ke;  // touches bin ke only at its lower edge
    sp.first = cut_lo ? cumulative<Dim>(lo - c, r) : 0.0;
    sp.last = cut_hi ? cumulative<Dim>(lo + nb * width - c, r) : full_volume<Dim>(r);
    return true;
}

// Bin k of the span collects C(e_{k+1}) - C(e_k), C the cumulative volume below edge e;
// inner(j) is C at the j-th inner edge lo + (kb+j+1) w.
template <int NV, bool Wide, class Inner>
inline void deposit_span(const Span& sp, Inner&& inner, const double* __restrict vals,
                         std::int64_t nv, double* __restrict vol,
                         double* __restrict sums) noexcept {
    double prev = sp.first;
    for (std::int64_t k = sp.kb; k < sp.ke; ++k) {
        // max(): keeps round-off from producing tiny negative overlaps
        const double cur = std::max(prev, inner(k - sp.kb));
        const double v = cur - prev;
        prev = cur;
        vol[k] += v;
        if constexpr (Wide) add_row_wide<NV>(sums + k * nv, vals, v, nv);
        else add_row<NV>(sums + k * nv, vals, v, nv);
    }
    const double v = std::max(0.0, sp.last - prev);
    vol[sp.ke] += v;
    if constexpr (Wide) add_row_wide<NV>(sums + sp.ke * nv, vals, v, nv);
    else add_row<NV>(sums + sp.ke * nv, vals, v, nv);
}

// One particle (or periodic image) centred at c against bins [lo + b w, lo + (b+1) w).
// Bin k collects C(e_{k+1}) - C(e_k), C the cumulative volume below edge e; edges strictly
// inside the particle go through cumulative_inside, the outer ones are 0 / full volume
// unless the grid ends cut the particle (then the part beyond the grid is dropped).
template <int Dim, int NV>
inline void deposit(double c, double r, const double* __restrict vals, std::int64_t nv,
                    double lo, double width, double inv_width, std::int64_t nbins,
                    double* __restrict vol, double* __restrict sums) noexcept {
    Span sp;
    if (!find_span<Dim>(c, r, lo, width, inv_width, nbins, sp)) return;
    const auto inner = [&](std::int64_t j) {
        return cumulative_inside<Dim>(lo + static_cast<double>(sp.kb + j + 1) * width - c, r);
    };
    deposit_span<NV, false>(sp, inner, vals, nv, vol, sums);
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

    // c wrapped into [lo, lo + period) (period > 0)
    double wrap(double c) const noexcept {
        if (c >= lo && c < lo + period) return c;
        double c0 = c - period * std::floor((c - lo) * inv_period);
        if (c0 >= lo + period) c0 -= period;
        return c0 < lo ? lo : c0;
    }
};

// Calls image(c') for the particle itself (period == 0) or for each of its periodic images
// that may reach the bins (period > 0). Same image rules as deposit_particle, which keeps its
// own copy because routing the 3D path through this lambda made it ~8 % slower (GCC 12).
template <class Image>
inline void for_each_image(double c, double r, const Grid& g, Image&& image) {
    if (g.period <= 0.0) {
        image(c);
        return;
    }
    const double p = g.period;
    const double c0 = g.wrap(c);
    image(c0);
    if (2.0 * r <= p && g.one_period) {  // at most one other image reaches the bins
        if (c0 - r < g.lo)
            image(c0 + p);
        else if (c0 + r > g.lo + p)
            image(c0 - p);
        return;
    }
    // Particles wider than half the period, or bins beyond one period: every other image
    // c0 + k P that reaches into [lo, end].
    const auto kmin = static_cast<std::int64_t>(-std::ceil(r * g.inv_period));
    const auto kmax = static_cast<std::int64_t>(std::ceil((g.end + r - c0) * g.inv_period));
    for (std::int64_t k = kmin; k <= kmax; ++k)
        if (k != 0) image(c0 + static_cast<double>(k) * p);
}

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
    const double c0 = g.wrap(c);
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

// Discs in batches. Per particle the exact 2D overlaps need, at each bin edge inside the disc,
// a division, a square root and a polynomial; evaluated one edge at a time that is a long
// dependency chain per particle. Instead the inner edges of many consecutive particles are
// queued first (with each particle's span and value row), their cumulative areas computed in
// one branch-free loop (four lanes at a time in the AVX2 build), and then the spans are
// deposited in the order they were queued, so every bin receives the same additions in the
// same order as particle by particle. A span with more inner edges than a batch holds (huge
// disc or tiny bins) is deposited directly, after the queue is flushed.
template <int NV, int RowCap, class Row>
class DiscBinner {
  public:
    DiscBinner(const Grid& g, std::int64_t nv, const Row& row, double* vol, double* sums) noexcept
        : g_(g), nv_(nv), row_(row), vol_(vol), sums_(sums) {}

    // Queues particle i (image centred at c).
    DEMSTUDY_ALWAYS_INLINE void add(std::int64_t i, double c, double r) noexcept {
        Span sp;
        if (!find_span<2>(c, r, g_.lo, g_.width, g_.inv_width, g_.nbins, sp)) return;
        const std::int64_t nedges = sp.ke - sp.kb;
        if (nedges > kEdges - ne_ || nspans_ == kSpans) {
            flush();
            if (nedges > kEdges) return deposit_direct(sp, i, c, r);
        }
        Item& it = items_[nspans_];
        it.span = sp;
        it.vals = row_(i, rows_[nspans_]);
        it.e0 = ne_;
        ++nspans_;
        for (std::int64_t k = sp.kb; k < sp.ke; ++k) {
            s_[ne_] = g_.lo + static_cast<double>(k + 1) * g_.width - c;
            r_[ne_] = r;
            ++ne_;
        }
    }

    // Computes the queued edges and deposits the queued spans; empties the queue.
    DEMSTUDY_NOINLINE void flush() noexcept {
        for (int e = ne_; e % 4 != 0; ++e) {  // harmless padding for the 4-wide loop
            s_[e] = 0.0;
            r_[e] = 1.0;
        }
        disc_cumulative_batch(s_, r_, cum_, ne_);
        for (int n = 0; n < nspans_; ++n) {
            const Item& it = items_[n];
            const double* cum = cum_ + it.e0;
            deposit_span<NV, true>(it.span, [cum](std::int64_t j) { return cum[j]; }, it.vals,
                                   nv_, vol_, sums_);
        }
        ne_ = 0;
        nspans_ = 0;
    }

  private:
    static constexpr int kEdges = 256;  // inner edges per batch (a multiple of 4)
    static constexpr int kSpans = 128;

    DEMSTUDY_NOINLINE void deposit_direct(const Span& sp, std::int64_t i, double c,
                                          double r) noexcept {
        const auto inner = [&](std::int64_t j) {
            return disc_cumulative_inside(
                g_.lo + static_cast<double>(sp.kb + j + 1) * g_.width - c, r);
        };
        deposit_span<NV, false>(sp, inner, row_(i, rows_[0]), nv_, vol_, sums_);
    }

    struct Item {
        Span span;
        const double* vals;
        int e0;  // first inner edge in s_/r_/cum_
    };
    const Grid& g_;
    const std::int64_t nv_;
    const Row& row_;
    double* const vol_;
    double* const sums_;
    int ne_ = 0, nspans_ = 0;
    alignas(32) double s_[kEdges];
    alignas(32) double r_[kEdges];
    alignas(32) double cum_[kEdges];
    Item items_[kSpans];
    double rows_[kSpans][RowCap > 0 ? RowCap : 1];  // value rows built by row_
};

// Deposits every particle; row(i, scratch) gives the value row of particle i, either a
// pointer into the input or scratch (RowCap doubles) filled with it. Returns the number of
// skipped (bad) particles.
template <int Dim, int NV, int RowCap, class Row>
std::int64_t deposit_all(const double* coord, const double* radius, std::int64_t n,
                         std::int64_t nv, const Grid& g, const Row& row, double* __restrict vol,
                         double* __restrict sums) noexcept {
    std::int64_t skipped = 0;
    if constexpr (Dim == 3) {
        double scratch[RowCap > 0 ? RowCap : 1];
        for (std::int64_t i = 0; i < n; ++i) {
            const double c = coord[i], r = radius[i];
            if (bad_particle(c, r)) {
                ++skipped;
                continue;
            }
            deposit_particle<Dim, NV>(c, r, row(i, scratch), nv, g, vol, sums);
        }
    } else {
        DiscBinner<NV, RowCap, Row> binner(g, nv, row, vol, sums);
        for (std::int64_t i = 0; i < n; ++i) {
            const double c = coord[i], r = radius[i];
            if (bad_particle(c, r)) {
                ++skipped;
                continue;
            }
            if (g.period <= 0.0)
                binner.add(i, c, r);
            else
                for_each_image(c, r, g, [&](double ci) { binner.add(i, ci, r); });
        }
        binner.flush();
    }
    return skipped;
}

template <int Dim, int NV>
std::int64_t kernel(const double* coord, const double* radius, const double* values,
                    std::int64_t n, std::int64_t nv, double lo, double width, std::int64_t nbins,
                    double period, double* vol, double* sums) noexcept {
    const Grid g(lo, width, nbins, period);
    const auto row = [values, nv](std::int64_t i, double*) { return values + i * nv; };
    return deposit_all<Dim, NV, 0>(coord, radius, n, nv, g, row, vol, sums);
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
    const auto make_row = [radius, velocity, omega, k_inertia](std::int64_t i,
                                                               double* row) -> const double* {
        const double r = radius[i];
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
        return row;
    };
    return deposit_all<Dim, NV, NV>(coord, radius, n, NV, g, make_row, vol, sums);
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
