// Event-driven hard discs / spheres: see native/include/edmd/edmd.hpp.
// Dimensionless particle units: d = 1, m = 1, g = 1 when gravity acts.
#include "edmd/edmd.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>
#include <utility>

#if defined(__linux__)
#include <sys/mman.h>
#endif
#if defined(__x86_64__) && (defined(__GNUC__) || defined(__clang__)) && !defined(DEMSTUDY_EDMD_NO_AVX2)
#include <immintrin.h>
#define DEMSTUDY_EDMD_AVX2 1
#endif

namespace demstudy::edmd {

namespace {
inline double dot3(const double* a, const double* b) {
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}
inline void cross3(const double* a, const double* b, double* out) {
    out[0] = a[1] * b[2] - a[2] * b[1];
    out[1] = a[2] * b[0] - a[0] * b[2];
    out[2] = a[0] * b[1] - a[1] * b[0];
}
constexpr double kInfinity = std::numeric_limits<double>::infinity();

// Morton (Z-order) key of a cell: neighbouring cells along every axis stay close in memory
// order, unlike the row-major cell index (there a z neighbour is nx·ny cells away).
inline std::uint64_t spread3(std::uint64_t x) {
    x &= 0x1fffff;
    x = (x | x << 32) & 0x1f00000000ffffULL;
    x = (x | x << 16) & 0x1f0000ff0000ffULL;
    x = (x | x << 8) & 0x100f00f00f00f00fULL;
    x = (x | x << 4) & 0x10c30c30c30c30c3ULL;
    x = (x | x << 2) & 0x1249249249249249ULL;
    return x;
}
inline std::uint64_t morton(const std::int32_t* c) {
    return spread3(static_cast<std::uint64_t>(c[0])) |
           spread3(static_cast<std::uint64_t>(c[1])) << 1 |
           spread3(static_cast<std::uint64_t>(c[2])) << 2;
}

// v[k] <- v[perm[k]] for rows of `width` elements, in place (cycle following): no copy of
// the array, so re-sorting does not raise the peak memory.
template <typename V>
void permute_rows(V& v, std::size_t width, const std::vector<std::int32_t>& perm,
                  std::vector<char>& done) {
    const std::size_t n = perm.size();
    done.assign(n, 0);
    std::vector<typename V::value_type> tmp(width);
    for (std::size_t start = 0; start < n; ++start) {
        if (done[start]) continue;
        for (std::size_t a = 0; a < width; ++a) tmp[a] = v[width * start + a];
        std::size_t k = start;
        while (true) {
            done[k] = 1;
            const std::size_t from = static_cast<std::size_t>(perm[k]);
            if (from == start) break;
            for (std::size_t a = 0; a < width; ++a) v[width * k + a] = v[width * from + a];
            k = from;
        }
        for (std::size_t a = 0; a < width; ++a) v[width * k + a] = tmp[a];
    }
}

// Earliest t >= 0 at which y(t) = y0 + vy t + ay t²/2 reaches 0 while increasing (y0 <= 0:
// before the target). Roots in the cancellation-free forms. At or past the target (y0 >= 0,
// round-off or a penetration): now if moving on, else when the motion turns back onwards.
double first_hit(double y0, double vy, double ay) {
    if (y0 >= 0.0) {
        if (vy > 0.0) return 0.0;
        if (ay <= 0.0) return kInfinity;
        const double disc = vy * vy - 2.0 * ay * y0;
        return disc > 0.0 ? (-vy + std::sqrt(disc)) / ay : -vy / ay;
    }
    if (ay == 0.0) return vy > 0.0 ? -y0 / vy : kInfinity;
    const double disc = vy * vy - 2.0 * ay * y0;
    if (ay > 0.0) {
        const double s = std::sqrt(disc);
        return vy <= 0.0 ? (-vy + s) / ay : -2.0 * y0 / (vy + s);
    }
    if (vy <= 0.0 || disc < 0.0) return kInfinity;
    return -2.0 * y0 / (vy + std::sqrt(disc));
}
// The point in [lo, hi] where fn, monotone there and of opposite signs at the ends, changes
// sign: the last point on lo's side, to round-off (at most 100 halvings: 2^-100 of the span).
template <typename F>
double sign_change(F&& fn, double lo, double hi) {
    const bool lo_positive = fn(lo) > 0.0;
    for (int k = 0; k < 100; ++k) {
        const double mid = 0.5 * (lo + hi);
        if (!(mid > lo && mid < hi)) break;
        if ((fn(mid) > 0.0) == lo_positive)
            lo = mid;
        else
            hi = mid;
    }
    return lo;
}

// First contact time in [0, horizon] of a particle and a fixed bump under gravity: with the
// separation d(t) = d0 + dv t + ½ a t² (a = −g), f(t) = |d|² − σ² is a quartic. Its first
// crossing from apart (f > 0) to contact (f <= 0) is found exactly: the roots of f'' (a
// quadratic) split [0, horizon] into pieces where f' is monotone, bisection gives the roots
// of f' (where f turns), and f is then monotone between them, so the first piece that ends in
// contact holds the root, found by bisection to round-off (the last time still apart).
// Touching or overlapping and approaching: 0; in contact at a turning point and pressed on by
// gravity: that time (the engine gives a minimum rebound there, as on a flat wall). None
// before the horizon: inf.
double bump_contact_time(const double* d0, const double* dv, const double* a, double sigma,
                         double horizon) {
    const double d2 = dot3(d0, d0), f0 = d2 - sigma * sigma;
    const double b0 = dot3(d0, dv);
    if (f0 <= 0.0 && b0 < 0.0) return 0.0;
    const double aa = dot3(a, a), va = dot3(dv, a), vv = dot3(dv, dv), da = dot3(d0, a);
    // out of reach: the gap cannot close faster than |dv| t + |a| t²/2
    double h = horizon;
    if (!std::isfinite(h)) {  // the quartic's roots lie within Cauchy's bound
        const double c4 = 0.25 * aa;
        if (!(c4 > 0.0)) return kInfinity;
        h = 1.0 + std::max({std::fabs(va), std::fabs(vv + da), std::fabs(2.0 * b0),
                            std::fabs(f0)}) / c4;
    }
    const double gap = std::sqrt(d2) - sigma;
    if (gap > std::sqrt(vv) * h + 0.5 * std::sqrt(aa) * h * h) return kInfinity;
    auto separation_at = [&](double t, double d[3]) {
        for (int k = 0; k < 3; ++k) d[k] = d0[k] + (dv[k] + 0.5 * a[k] * t) * t;
    };
    auto f = [&](double t) {
        double d[3];
        separation_at(t, d);
        return dot3(d, d) - sigma * sigma;
    };
    auto df = [&](double t) {  // f'/2 = d·u
        double d[3], u[3];
        separation_at(t, d);
        for (int k = 0; k < 3; ++k) u[k] = dv[k] + a[k] * t;
        return dot3(d, u);
    };
    // f''/2 = 1.5 |a|² t² + 3 (dv·a) t + |dv|² + d0·a: its roots in (0, h), ascending
    double cuts[6];
    int n_cuts = 0;
    cuts[n_cuts++] = 0.0;
    {
        const double A = 1.5 * aa, B = 3.0 * va, C = vv + da;
        const double disc = B * B - 4.0 * A * C;
        if (A > 0.0 && disc > 0.0) {
            const double q = -0.5 * (B + std::copysign(std::sqrt(disc), B));
            double r1 = q / A, r2 = C / q;  // q != 0: disc > 0
            if (r1 > r2) std::swap(r1, r2);
            for (double r : {r1, r2})
                if (r > 0.0 && r < h) cuts[n_cuts++] = r;
        }
    }
    cuts[n_cuts++] = h;
    // the turning points of f (roots of f') in each piece where f' is monotone
    double turns[8];
    int n_turns = 0;
    turns[n_turns++] = 0.0;
    for (int k = 0; k + 1 < n_cuts; ++k) {
        const double lo = cuts[k], hi = cuts[k + 1];
        const double glo = df(lo), ghi = df(hi);
        if ((glo > 0.0) != (ghi > 0.0) && hi > lo) {
            const double r = sign_change(df, lo, hi);
            if (r > turns[n_turns - 1]) turns[n_turns++] = r;
        }
    }
    turns[n_turns++] = h;
    // the first piece of monotone f that goes from apart to contact, or that starts in
    // contact (round-off) and closes in further: there the pair meets at the piece's start
    for (int k = 0; k + 1 < n_turns; ++k) {
        const double lo = turns[k], hi = turns[k + 1];
        const double flo = f(lo), fhi = f(hi);
        if (flo > 0.0 && !(fhi > 0.0)) return sign_change(f, lo, hi);
        if (!(flo > 0.0) && fhi < flo) {
            // in contact and closing: only gravity can close a contact from a turning point, so
            // the particle is pressed onto the bump (the engine then gives it the minimum
            // rebound); a decrease with no pressing is round-off
            double d[3];
            separation_at(lo, d);
            if (dot3(d, a) < 0.0) return lo;
        }
    }
    return kInfinity;
}
}  // namespace

namespace {

// Collision times of particle i (state xi, vi at time `now`, radius ri) with the candidates
// js[0..n) of the same image (no shift): out[q] = time from now, 0 if touching or overlapping
// and approaching, +inf if they do not meet. Pair times do not depend on gravity, but the
// candidates' positions and velocities are extrapolated to `now` along their parabolas
// (hg = g/2; G = false: no gravity, the same numbers without the g terms). The scalar and the
// AVX2 versions do the same IEEE operations in the same order (no FMA), so they give identical
// bits and the run does not depend on which one the CPU gets.
template <bool G>
void pair_times_scalar(const PairRecord* P, const std::int32_t* js, int n, const double* xi,
                       const double* vi, double ri, double now, const double* g,
                       const double* hg, double* out) {
    for (int q = 0; q < n; ++q) {
        const PairRecord& p = P[js[q]];
        const double dt = now - p.t;
        double dr[3], dv[3];
        for (int a = 0; a < 3; ++a) {
            if constexpr (G) {
                dr[a] = p.x[a] + (p.v[a] + hg[a] * dt) * dt - xi[a];
                dv[a] = p.v[a] + g[a] * dt - vi[a];
            } else {
                dr[a] = p.x[a] + p.v[a] * dt - xi[a];
                dv[a] = p.v[a] - vi[a];
            }
        }
        const double b = dot3(dr, dv);
        double t = kInfinity;
        if (b < 0.0) {
            const double sigma = ri + p.r;
            const double cc = dot3(dr, dr) - sigma * sigma;
            if (cc <= 0.0) {
                t = 0.0;  // touching or overlapping and approaching: collide now
            } else {
                const double disc = b * b - dot3(dv, dv) * cc;
                if (disc > 0.0) t = cc / (std::sqrt(disc) - b);
            }
        }
        out[q] = t;
    }
}

#ifdef DEMSTUDY_EDMD_AVX2
// Four candidates at a time: each 64-byte record is two 256-bit loads, transposed into
// columns (x0, x1, x2, v0 | v1, v2, t, r).
template <bool G>
__attribute__((target("avx2"))) void pair_times_avx2(const PairRecord* P, const std::int32_t* js,
                                                     int n, const double* xi, const double* vi,
                                                     double ri, double now, const double* g,
                                                     const double* hg, double* out) {
    const __m256d vnow = _mm256_set1_pd(now), vri = _mm256_set1_pd(ri);
    const __m256d zero = _mm256_setzero_pd(), inf = _mm256_set1_pd(kInfinity);
    const __m256d x0i = _mm256_set1_pd(xi[0]), x1i = _mm256_set1_pd(xi[1]),
                  x2i = _mm256_set1_pd(xi[2]);
    const __m256d v0i = _mm256_set1_pd(vi[0]), v1i = _mm256_set1_pd(vi[1]),
                  v2i = _mm256_set1_pd(vi[2]);
    int q = 0;
    for (; q + 4 <= n; q += 4) {
        const double* p0 = P[js[q]].x;
        const double* p1 = P[js[q + 1]].x;
        const double* p2 = P[js[q + 2]].x;
        const double* p3 = P[js[q + 3]].x;
        const __m256d a0 = _mm256_load_pd(p0), a1 = _mm256_load_pd(p1);
        const __m256d a2 = _mm256_load_pd(p2), a3 = _mm256_load_pd(p3);
        const __m256d b0 = _mm256_load_pd(p0 + 4), b1 = _mm256_load_pd(p1 + 4);
        const __m256d b2 = _mm256_load_pd(p2 + 4), b3 = _mm256_load_pd(p3 + 4);
        const __m256d al01 = _mm256_unpacklo_pd(a0, a1), ah01 = _mm256_unpackhi_pd(a0, a1);
        const __m256d al23 = _mm256_unpacklo_pd(a2, a3), ah23 = _mm256_unpackhi_pd(a2, a3);
        const __m256d bl01 = _mm256_unpacklo_pd(b0, b1), bh01 = _mm256_unpackhi_pd(b0, b1);
        const __m256d bl23 = _mm256_unpacklo_pd(b2, b3), bh23 = _mm256_unpackhi_pd(b2, b3);
        const __m256d x0 = _mm256_permute2f128_pd(al01, al23, 0x20);
        const __m256d x2 = _mm256_permute2f128_pd(al01, al23, 0x31);
        const __m256d x1 = _mm256_permute2f128_pd(ah01, ah23, 0x20);
        __m256d v0 = _mm256_permute2f128_pd(ah01, ah23, 0x31);
        __m256d v1 = _mm256_permute2f128_pd(bl01, bl23, 0x20);
        const __m256d tj = _mm256_permute2f128_pd(bl01, bl23, 0x31);
        __m256d v2 = _mm256_permute2f128_pd(bh01, bh23, 0x20);
        const __m256d rj = _mm256_permute2f128_pd(bh01, bh23, 0x31);
        const __m256d dt = _mm256_sub_pd(vnow, tj);
        __m256d dr0, dr1, dr2;
        if constexpr (G) {
            // x + (v + hg dt) dt − xi, then v + g dt
            dr0 = _mm256_sub_pd(_mm256_add_pd(x0, _mm256_mul_pd(_mm256_add_pd(v0, _mm256_mul_pd(_mm256_set1_pd(hg[0]), dt)), dt)), x0i);
            dr1 = _mm256_sub_pd(_mm256_add_pd(x1, _mm256_mul_pd(_mm256_add_pd(v1, _mm256_mul_pd(_mm256_set1_pd(hg[1]), dt)), dt)), x1i);
            dr2 = _mm256_sub_pd(_mm256_add_pd(x2, _mm256_mul_pd(_mm256_add_pd(v2, _mm256_mul_pd(_mm256_set1_pd(hg[2]), dt)), dt)), x2i);
            v0 = _mm256_add_pd(v0, _mm256_mul_pd(_mm256_set1_pd(g[0]), dt));
            v1 = _mm256_add_pd(v1, _mm256_mul_pd(_mm256_set1_pd(g[1]), dt));
            v2 = _mm256_add_pd(v2, _mm256_mul_pd(_mm256_set1_pd(g[2]), dt));
        } else {
            dr0 = _mm256_sub_pd(_mm256_add_pd(x0, _mm256_mul_pd(v0, dt)), x0i);
            dr1 = _mm256_sub_pd(_mm256_add_pd(x1, _mm256_mul_pd(v1, dt)), x1i);
            dr2 = _mm256_sub_pd(_mm256_add_pd(x2, _mm256_mul_pd(v2, dt)), x2i);
        }
        const __m256d dv0 = _mm256_sub_pd(v0, v0i), dv1 = _mm256_sub_pd(v1, v1i),
                      dv2 = _mm256_sub_pd(v2, v2i);
        const __m256d b = _mm256_add_pd(_mm256_add_pd(_mm256_mul_pd(dr0, dv0), _mm256_mul_pd(dr1, dv1)),
                                        _mm256_mul_pd(dr2, dv2));
        const __m256d sigma = _mm256_add_pd(vri, rj);
        const __m256d cc = _mm256_sub_pd(
            _mm256_add_pd(_mm256_add_pd(_mm256_mul_pd(dr0, dr0), _mm256_mul_pd(dr1, dr1)),
                          _mm256_mul_pd(dr2, dr2)),
            _mm256_mul_pd(sigma, sigma));
        const __m256d aa = _mm256_add_pd(_mm256_add_pd(_mm256_mul_pd(dv0, dv0), _mm256_mul_pd(dv1, dv1)),
                                         _mm256_mul_pd(dv2, dv2));
        const __m256d disc = _mm256_sub_pd(_mm256_mul_pd(b, b), _mm256_mul_pd(aa, cc));
        const __m256d root = _mm256_sqrt_pd(_mm256_max_pd(disc, zero));
        __m256d t = _mm256_div_pd(cc, _mm256_sub_pd(root, b));
        const __m256d touching = _mm256_cmp_pd(cc, zero, _CMP_LE_OQ);
        t = _mm256_blendv_pd(t, zero, touching);
        // a miss: receding (b >= 0), or apart with no real root (cc > 0, disc <= 0)
        const __m256d miss = _mm256_or_pd(
            _mm256_cmp_pd(b, zero, _CMP_GE_OQ),
            _mm256_andnot_pd(touching, _mm256_cmp_pd(disc, zero, _CMP_LE_OQ)));
        _mm256_storeu_pd(out + q, _mm256_blendv_pd(t, inf, miss));
    }
    if (q < n) pair_times_scalar<G>(P, js + q, n - q, xi, vi, ri, now, g, hg, out + q);
}

bool cpu_has_avx2() noexcept { return __builtin_cpu_supports("avx2"); }
bool g_pair_simd = cpu_has_avx2();
#endif

}  // namespace

bool set_pair_simd(bool enabled) noexcept {
#ifdef DEMSTUDY_EDMD_AVX2
    g_pair_simd = enabled && cpu_has_avx2();
    return g_pair_simd;
#else
    (void)enabled;
    return false;
#endif
}

void pair_times(bool gravity, const PairRecord* P, const std::int32_t* js, int n,
                const double* xi, const double* vi, double ri, double now, const double* g,
                double* out) {
    const double hg[3] = {0.5 * g[0], 0.5 * g[1], 0.5 * g[2]};
#ifdef DEMSTUDY_EDMD_AVX2
    if (g_pair_simd) {
        if (gravity)
            pair_times_avx2<true>(P, js, n, xi, vi, ri, now, g, hg, out);
        else
            pair_times_avx2<false>(P, js, n, xi, vi, ri, now, g, hg, out);
        return;
    }
#endif
    if (gravity)
        pair_times_scalar<true>(P, js, n, xi, vi, ri, now, g, hg, out);
    else
        pair_times_scalar<false>(P, js, n, xi, vi, ri, now, g, hg, out);
}

void advise_huge_pages(void* p, std::size_t bytes) noexcept {
#if defined(__linux__) && defined(MADV_HUGEPAGE)
    constexpr std::uintptr_t kHuge = std::uintptr_t{1} << 21;
    if (bytes < 2 * kHuge) return;
    const std::uintptr_t lo = (reinterpret_cast<std::uintptr_t>(p) + kHuge - 1) & ~(kHuge - 1);
    const std::uintptr_t hi = (reinterpret_cast<std::uintptr_t>(p) + bytes) & ~(kHuge - 1);
    if (hi > lo) madvise(reinterpret_cast<void*>(lo), hi - lo, MADV_HUGEPAGE);  // advice only
#else
    (void)p;
    (void)bytes;
#endif
}

double Rule::restitution(double gn) const {
    switch (law) {
        case kCampbellExp:
            return 0.5 * (1.0 + std::exp(-gn / speed));
        case kGutt:
            // c_r = e1 c for c <= c_b, e1 c_b + e2 (c - c_b) above
            return gn <= crossover || gn <= 0.0 ? e1 : (e1 * crossover + e2 * (gn - crossover)) / gn;
        default:
            return e;
    }
}

double Rule::beta_for(double e_n, double k, double gn, double gt) const {
    if (tangential != kCoulomb) return beta;
    // Walton: sticking (β₀) unless the tangential impulse would exceed μ times the normal one
    const double b0 = beta0_from_e ? e_n : beta0;  // default β₀ = e (docs/contact.md)
    if (k <= 0.0 || gt <= 0.0) return b0;
    const double sliding = -1.0 + mu * (1.0 + e_n) * (1.0 + 1.0 / k) * gn / gt;
    return std::min(b0, sliding);
}

void collide(const double n[3], double ri, double rj, double im_i, double im_j,
             double inertia_k, double e, double beta, double vi[3], double vj[3], double wi[3],
             double wj[3], double J[3]) {
    // relative velocity of the contact points, g = vi - vj + (ri wi + rj wj) x n
    double s[3], sxn[3], g[3];
    for (int a = 0; a < 3; ++a) s[a] = ri * wi[a] + (im_j > 0.0 ? rj * wj[a] : 0.0);
    cross3(s, n, sxn);
    for (int a = 0; a < 3; ++a) g[a] = vi[a] - vj[a] + sxn[a];
    const double gn = dot3(g, n);
    const double meff = 1.0 / (im_i + im_j);
    const bool rotating = inertia_k > 0.0 && beta > -1.0;
    const double ct = rotating ? meff * (1.0 + beta) * inertia_k / (1.0 + inertia_k) : 0.0;
    for (int a = 0; a < 3; ++a) {
        const double gt = g[a] - gn * n[a];
        J[a] = -meff * (1.0 + e) * gn * n[a] - ct * gt;
    }
    for (int a = 0; a < 3; ++a) {
        vi[a] += J[a] * im_i;
        vj[a] -= J[a] * im_j;
    }
    if (rotating) {
        double nxj[3];
        cross3(n, J, nxj);
        const double fi = im_i / (inertia_k * ri);
        for (int a = 0; a < 3; ++a) wi[a] += fi * nxj[a];
        if (im_j > 0.0) {
            const double fj = im_j / (inertia_k * rj);
            for (int a = 0; a < 3; ++a) wj[a] += fj * nxj[a];
        }
    }
}

EventDriven::EventDriven(const Params& p, std::int64_t n, const double* pos, const double* vel,
                         const double* omega, const double* diameter, const double* mass)
    : p_(p), n_(n) {
    if (p.dim != 2 && p.dim != 3) throw std::invalid_argument("dim must be 2 or 3");
    auto check_rule = [](const Rule& r, const std::string& who) {
        const bool ok_e = r.law == Rule::kConstant ? (r.e > 0.0 && r.e <= 1.0)
                          : r.law == Rule::kCampbellExp ? r.speed > 0.0
                          : r.law == Rule::kGutt ? (r.e1 >= 0.0 && r.e1 <= 1.0 && r.e2 >= 0.0 &&
                                                     r.e2 <= 1.0 && r.crossover > 0.0)
                                                  : false;
        if (!ok_e) throw std::invalid_argument(who + " restitution must be in (0, 1]");
        if (!(r.beta >= -1.0 && r.beta <= 1.0) || !(r.beta0 >= -1.0 && r.beta0 <= 1.0))
            throw std::invalid_argument(who + " beta must be in [-1, 1]");
        if (!(r.mu >= 0.0)) throw std::invalid_argument(who + " mu must be >= 0");
    };
    check_rule(p.pair, "pair");
    if (p.pair.tangential == Rule::kNoSlip)
        throw std::invalid_argument("the no-slip rule is for walls only");
    if (!(p.inertia_k >= 0.0)) throw std::invalid_argument("inertia_k must be >= 0");
    if (!(p.tc >= 0.0)) throw std::invalid_argument("tc must be >= 0");
    if (n < 1 || n > (std::int64_t{1} << 30)) throw std::invalid_argument("need 1 <= N < 2^30");
    for (int a = 0; a < 3; ++a)
        if (!std::isfinite(p.gravity[a])) throw std::invalid_argument("gravity must be finite");
    if (p.dim == 2) {
        p_.box[2] = 1.0;
        p_.gravity[2] = 0.0;
    }
    gravity_ = p_.gravity[0] != 0.0 || p_.gravity[1] != 0.0 || p_.gravity[2] != 0.0;
    if (!(p.shear_rate >= 0.0) || !std::isfinite(p.shear_rate))
        throw std::invalid_argument("shear_rate must be finite and >= 0 (0: no shear)");
    if (p.shear_rate != 0.0 && !p.periodic_y)
        throw std::invalid_argument("Lees-Edwards shear needs a periodic y");
    if (p.periodic_y) {
        p_.wall[0].present = p_.wall[1].present = false;
    } else {
        for (int s = 0; s < 2; ++s)
            if (p.wall[s].present) check_rule(p.wall[s].rule, s == 0 ? "lower wall" : "upper wall");
        if (!(p.y_hi > p.y_lo)) throw std::invalid_argument("y_hi must exceed y_lo");
    }
    check_stress_bins(p.stress_lo, p.stress_width, static_cast<double>(p.stress_bins),
                      "stress bins");
    if (!p.fixed.empty()) {
        if (static_cast<std::int64_t>(p.fixed.size()) != n)
            throw std::invalid_argument("fixed needs one entry per particle");
        for (auto f : p.fixed) {
            if (f < 0 || f > 2) throw std::invalid_argument("fixed entries are 0, 1 or 2");
            if (f > 0 && (!p.wall[f - 1].present || p.periodic_y))
                throw std::invalid_argument("bumps need their wall");
            if (f > 0 && p.wall[f - 1].rule.tangential == Rule::kNoSlip)
                throw std::invalid_argument("bumps cannot use the no-slip rule");
        }
    }
    if (p.log_every < 0 || p.log_capacity < 0)
        throw std::invalid_argument("log_every and log_capacity must be >= 0");
    stress_.assign(static_cast<std::size_t>(9 * p.stress_bins), 0.0);
    const std::size_t N = static_cast<std::size_t>(n);
    const int nrot = p.dim == 2 ? 1 : 3;
    // wrapped input position (periodic axes)
    auto wrapped = [&](std::size_t i, int a) {
        double x = pos[i * p.dim + a];
        if (a != 1 || p_.periodic_y) {
            const double L = p_.box[a];
            x = x - L * std::floor(x / L);
            if (x >= L) x -= L;
        }
        return x;
    };
    dmax_ = 0.0;
    for (std::size_t i = 0; i < N; ++i) {
        for (int a = 0; a < p.dim; ++a)
            if (!std::isfinite(pos[i * p.dim + a]) || !std::isfinite(vel[i * p.dim + a]))
                throw std::invalid_argument("non-finite position or velocity");
        for (int a = 0; a < nrot; ++a)
            if (!std::isfinite(omega[i * nrot + a]))
                throw std::invalid_argument("non-finite angular velocity");
        if (!(diameter[i] > 0.0) || !(mass[i] > 0.0) || !std::isfinite(diameter[i]) ||
            !std::isfinite(mass[i]))
            throw std::invalid_argument("diameters and masses must be finite and positive");
        dmax_ = std::max(dmax_, diameter[i]);
    }
    setup_grid();
    // internal order: by cell, in Morton order (neighbours close in memory); order_[internal]
    // = input index. Sorted before the particle arrays exist (keeps the peak memory low),
    // then every array is filled in that order.
    book_.assign(N + 1, Book{});
    for (std::size_t i = 0; i < N; ++i)
        for (int a = 0; a < p.dim; ++a) book_[i].cell[a] = cell_of(wrapped(i, a), a);
    sort_by_cell(order_);
    {
        std::vector<char> done;
        book_.pop_back();  // the system slot stays last
        permute_rows(book_, 1, order_, done);
        book_.push_back(Book{});
    }
    P_.assign(N, Particle{});
    spin_.assign(N, Spin{});
    for (std::size_t k = 0; k < N; ++k) {
        const std::size_t i = static_cast<std::size_t>(order_[k]);
        for (int a = 0; a < p.dim; ++a) {
            P_[k].x[a] = wrapped(i, a);
            P_[k].v[a] = vel[i * p.dim + a];
        }
        if (nrot == 1)
            spin_[k].w[2] = omega[i];
        else
            for (int a = 0; a < 3; ++a) spin_[k].w[a] = omega[3 * i + a];
        P_[k].r = 0.5 * diameter[i];
        spin_[k].m = mass[i];
        if (!p.fixed.empty()) book_[k].fixed = p.fixed[i];
    }
    p_.fixed.clear();
    p_.fixed.shrink_to_fit();
    for (std::size_t k = 0; k < N; ++k) {
        if (book_[k].fixed == 0) continue;
        has_bumps_ = true;
        if (gravity_ && (P_[k].v[0] != 0.0 || P_[k].v[1] != 0.0 || P_[k].v[2] != 0.0))
            throw std::invalid_argument("bumps under gravity must be static (their wall at "
                                        "rest)");
    }
    build_cells();
    heap_.assign(N + 1 + kHeapPad, Node{kInf, -1});
    for (std::int32_t k = 0; k <= static_cast<std::int32_t>(n_); ++k) {
        node_at(k) = Node{kInf, k};
        book_[k].pos_in_heap = k;
    }
    predict_all();
    schedule_system();
    heap_build();
}

// Cells: width >= the largest diameter, >= 3 per periodic axis, at most ~8 per particle. A
// non-periodic y is covered from y_lo to y_hi; its first and last rows are open-ended. Over
// the cell budget, the axis with the most cells is coarsened first (each axis has its own
// width), so a few particles in an elongated box keep 3 cells along its short periodic axes.
void EventDriven::setup_grid() {
    // counted in floating point: a huge box must not overflow the cell counts
    const double cap = static_cast<double>(std::max<std::int64_t>(8 * n_, 64));
    double cells[3] = {1.0, 1.0, 1.0};
    double least[3] = {1.0, 1.0, 1.0};
    for (int a = 0; a < p_.dim; ++a) {
        const bool periodic = a != 1 || p_.periodic_y;
        const double L = periodic ? p_.box[a] : p_.y_hi - p_.y_lo;
        cells[a] = std::clamp(std::floor(L / dmax_), 1.0, 1e9);
        least[a] = periodic ? 3.0 : 1.0;
        if (periodic && cells[a] < 3.0)
            throw std::invalid_argument(
                "every periodic box length must be at least 3 largest particle diameters "
                "(axis " + std::to_string(a) + ": " + std::to_string(p_.box[a]) +
                "; largest diameter " + std::to_string(dmax_) + ")");
    }
    for (int iter = 0; iter < 100000; ++iter) {
        double total = 1.0;
        int most = -1;
        for (int a = 0; a < p_.dim; ++a) {
            total *= cells[a];
            if (cells[a] > least[a] && (most < 0 || cells[a] > cells[most])) most = a;
        }
        if (total <= cap || most < 0) break;  // at the floor: 27 cells or fewer, under cap
        cells[most] = std::max(least[most], std::floor(cells[most] / 1.1));
    }
    for (int a = 0; a < p_.dim; ++a) {
        const bool periodic = a != 1 || p_.periodic_y;
        ncell_[a] = static_cast<int>(cells[a]);
        const double L = periodic ? p_.box[a] : p_.y_hi - p_.y_lo;
        cw_[a] = L / ncell_[a];
        org_[a] = periodic ? 0.0 : p_.y_lo;
    }
    if (p_.dim == 2) {
        ncell_[2] = 1;
        cw_[2] = p_.box[2];
        org_[2] = 0.0;
    }
    for (int& count : n_nb_) count = 0;
    const int zr = p_.dim == 3 ? 1 : 0;
    for (int dz = -zr; dz <= zr; ++dz)
        for (int dy = -1; dy <= 1; ++dy)
            for (int dx = -1; dx <= 1; ++dx) {
                const std::int64_t off = (static_cast<std::int64_t>(dz) * ncell_[1] + dy) * ncell_[0] + dx;
                const int d[3] = {dx, dy, dz};
                nb_off_[0][n_nb_[0]++] = off;
                for (int a = 0; a < 3; ++a)
                    if (d[a] != 0) {
                        const int list = 1 + 2 * a + (d[a] > 0);
                        nb_off_[list][n_nb_[list]++] = off;
                    }
            }
}

int EventDriven::cell_of(double x, int axis) const {
    const int c = static_cast<int>(std::floor((x - org_[axis]) / cw_[axis]));
    return std::clamp(c, 0, ncell_[axis] - 1);
}

void EventDriven::build_cells() {
    const std::int64_t total = static_cast<std::int64_t>(ncell_[0]) * ncell_[1] * ncell_[2];
    head_.assign(static_cast<std::size_t>(total), -1);
    next_.assign(static_cast<std::size_t>(n_), -1);
    prev_.assign(static_cast<std::size_t>(n_), -1);
    for (std::int32_t i = static_cast<std::int32_t>(n_) - 1; i >= 0; --i) insert_cell(i);
}

void EventDriven::insert_cell(std::int32_t i) {
    const std::int64_t c = cell_index(book_[i].cell);
    const std::int32_t h = head_[c];
    next_[i] = h;
    prev_[i] = -1;
    if (h >= 0) prev_[h] = i;
    head_[c] = i;
}

void EventDriven::remove_cell(std::int32_t i) {
    if (prev_[i] >= 0)
        next_[prev_[i]] = next_[i];
    else
        head_[cell_index(book_[i].cell)] = next_[i];
    if (next_[i] >= 0) prev_[next_[i]] = prev_[i];
}

void EventDriven::state_at(std::int32_t i, double tt, double x[3], double v[3]) const {
    const double dt = tt - P_[i].t;
    const double* g = grav(i);
    for (int a = 0; a < 3; ++a) {
        x[a] = P_[i].x[a] + (P_[i].v[a] + 0.5 * g[a] * dt) * dt;
        v[a] = P_[i].v[a] + g[a] * dt;
    }
}

void EventDriven::advance(std::int32_t i, double t) {
    const double dt = t - P_[i].t;
    if (dt == 0.0) return;
    if (gravity_ && book_[i].fixed == 0) {  // bumps feel no gravity
        const double* g = p_.gravity;
        double dx[3];
        for (int a = 0; a < 3; ++a) {
            dx[a] = (P_[i].v[a] + 0.5 * g[a] * dt) * dt;
            P_[i].x[a] += dx[a];
            P_[i].v[a] += g[a] * dt;
        }
        gravity_work_ += spin_[i].m * dot3(g, dx);
    } else {
        for (int a = 0; a < 3; ++a) P_[i].x[a] += P_[i].v[a] * dt;
    }
    P_[i].t = t;
}

double EventDriven::le_delta(double t) const {
    return le_cell_ * cw_[0] + p_.shear_rate * p_.box[1] * (t - le_t_);
}

double EventDriven::shear_offset() const {
    if (p_.shear_rate == 0.0) return 0.0;
    const double L = p_.box[0];
    double d = le_delta(time_);
    d -= L * std::floor(d / L);
    return d >= L ? d - L : d;
}

// Separation dr = r_j - r_i at time_ (j's nearest image: cell offsets along y, minimum image
// along x and z) and the velocity shift vs of that image (Lees–Edwards: ± rate Ly along x).
void EventDriven::separation(std::int32_t i, std::int32_t j, double dr[3], double vs[3]) const {
    double xi[3], vi[3], xj[3], vj[3];
    state_at(i, time_, xi, vi);
    state_at(j, time_, xj, vj);
    vs[0] = vs[1] = vs[2] = 0.0;
    for (int a = 0; a < 3; ++a) dr[a] = xj[a] - xi[a];
    if (p_.periodic_y) {
        const int dc = book_[j].cell[1] - book_[i].cell[1];
        const int side = dc < -1 ? 1 : dc > 1 ? -1 : 0;  // j's image above (+1) or below (-1)
        if (side != 0) {
            dr[1] += side * p_.box[1];
            dr[0] += side * le_delta(time_);
            vs[0] = side * p_.shear_rate * p_.box[1];
        }
    }
    for (int a = 0; a < p_.dim; ++a) {
        if (a == 1) continue;
        dr[a] -= p_.box[a] * std::nearbyint(dr[a] / p_.box[a]);
    }
    if (p_.dim == 2) dr[2] = 0.0;
}

// Visit the particles j of the neighbouring cells of i (only the layer at offset `dir` along
// `only_axis` when only_axis >= 0) with the shift of j's image: visit(j, shift, vshift), where
// shift == nullptr means no shift (the common case, so the caller's arithmetic for it folds
// away). Across a Lees–Edwards boundary the image row slides: 6 x-cells cover every partner
// that can come within reach until the next re-scan (the offset moves by one cell width
// between them).
template <typename F>
void EventDriven::for_neighbours(std::int32_t i, int only_axis, int dir, F&& visit) const {
    const std::int32_t* ci = book_[i].cell;
    // fast path: every neighbour cell inside the grid (no image shift, fixed index offsets)
    bool interior = true;
    for (int a = 0; a < p_.dim; ++a) interior = interior && ci[a] >= 1 && ci[a] + 1 < ncell_[a];
    if (interior) {
        const std::int64_t base = cell_index(ci);
        const int list = only_axis < 0 ? 0 : 1 + 2 * only_axis + (dir > 0);
        const std::int64_t* off = nb_off_[list];
        for (int k = 0, nk = n_nb_[list]; k < nk; ++k)
            for (std::int32_t j = head_[base + off[k]]; j >= 0; j = next_[j])
                if (j != i) visit(j, nullptr, nullptr);
        return;
    }
    static constexpr double zero[3] = {0.0, 0.0, 0.0};
    if (!le_row(i)) {
        // a border cell: per axis the (up to) three neighbour coordinates, wrapped, and the
        // shift of their images; rows beyond a non-periodic y are absent
        std::int32_t cell[3][3];
        double shift[3][3];
        int count[3];
        for (int a = 0; a < 3; ++a) {
            count[a] = 0;
            if (a >= p_.dim) {
                cell[a][0] = ci[a];
                shift[a][0] = 0.0;
                count[a] = 1;
                continue;
            }
            const bool periodic = a != 1 || p_.periodic_y;
            for (int d = -1; d <= 1; ++d) {
                if (only_axis == a && d != dir) continue;
                std::int32_t c = ci[a] + d;
                double s = 0.0;
                if (c < 0 || c >= ncell_[a]) {
                    if (!periodic) continue;
                    s = c < 0 ? -p_.box[a] : p_.box[a];
                    c += c < 0 ? ncell_[a] : -ncell_[a];
                }
                cell[a][count[a]] = c;
                shift[a][count[a]++] = s;
            }
        }
        // two passes, as in the batched scan: walk the lists prefetching the records, then
        // visit (the misses overlap)
        constexpr int kBatch = 64;
        std::int32_t js[kBatch];
        double shs[kBatch][3];
        int nb = 0;
        for (int kz = 0; kz < count[2]; ++kz)
            for (int ky = 0; ky < count[1]; ++ky)
                for (int kx = 0; kx < count[0]; ++kx) {
                    const std::int32_t c[3] = {cell[0][kx], cell[1][ky], cell[2][kz]};
                    for (std::int32_t j = head_[cell_index(c)]; j >= 0; j = next_[j]) {
                        if (j == i) continue;
                        __builtin_prefetch(&P_[j]);
                        js[nb] = j;
                        shs[nb][0] = shift[0][kx];
                        shs[nb][1] = shift[1][ky];
                        shs[nb][2] = shift[2][kz];
                        if (++nb == kBatch) {
                            for (int q = 0; q < nb; ++q) visit(js[q], shs[q], zero);
                            nb = 0;
                        }
                    }
                }
        for (int q = 0; q < nb; ++q) visit(js[q], shs[q], zero);
        return;
    }
    // a row next to the Lees–Edwards boundary
    const int zr = p_.dim == 3 ? 1 : 0;
    for (int dz = -zr; dz <= zr; ++dz) {
        if (only_axis == 2 && dz != dir) continue;
        for (int dy = -1; dy <= 1; ++dy) {
            if (only_axis == 1 && dy != dir) continue;
            std::int32_t c[3] = {0, ci[1] + dy, ci[2] + dz};
            double shift[3] = {0.0, 0.0, 0.0}, vshift[3] = {0.0, 0.0, 0.0};
            int side = 0;
            if (c[1] < 0 || c[1] >= ncell_[1]) {
                side = c[1] < 0 ? -1 : 1;
                c[1] -= side * ncell_[1];
                shift[1] = side * p_.box[1];
            }
            if (dz != 0) {
                if (c[2] < 0) {
                    c[2] += ncell_[2];
                    shift[2] = -p_.box[2];
                } else if (c[2] >= ncell_[2]) {
                    c[2] -= ncell_[2];
                    shift[2] = p_.box[2];
                }
            }
            int x0 = ci[0] - 1, x1 = ci[0] + 1;
            if (side != 0) {
                shift[0] = side * le_delta(time_);
                vshift[0] = side * p_.shear_rate * p_.box[1];
                if (side > 0) {
                    x0 = ci[0] - 3 - le_cell_;
                    x1 = ci[0] + 2 - le_cell_;
                } else {
                    x0 = ci[0] - 2 + le_cell_;
                    x1 = ci[0] + 3 + le_cell_;
                }
            }
            for (int cu = x0; cu <= x1; ++cu) {
                if (only_axis == 0 && cu - ci[0] != dir) continue;
                const int nx = ncell_[0];
                int wraps = 0;  // cu is within a few cells of [0, nx): no integer division
                c[0] = cu;
                while (c[0] < 0) {
                    c[0] += nx;
                    --wraps;
                }
                while (c[0] >= nx) {
                    c[0] -= nx;
                    ++wraps;
                }
                const double s0 = shift[0] + wraps * p_.box[0];
                const double sh[3] = {s0, shift[1], shift[2]};
                for (std::int32_t j = head_[cell_index(c)]; j >= 0; j = next_[j])
                    if (j != i) visit(j, sh, vshift);
            }
        }
    }
}

// Scan the neighbours of i and lower i's collision candidate (co_*) where a partner hits
// earlier. Pair collision times do not depend on gravity (both partners fall alike).
void EventDriven::scan(std::int32_t i, int only_axis, int dir) {
    const double* xi = P_[i].x;  // i is synchronised to time_
    const double* vi = P_[i].v;
    const double ri = P_[i].r;
    double best = book_[i].co_t - time_;  // relative to now (inf when there is no candidate)
    std::int32_t partner = book_[i].co_partner;
    std::int64_t partner_count = book_[i].co_count;
    const bool i_fixed = book_[i].fixed != 0;
    auto consider = [&](std::int32_t j, const double* dr, const double* dv) {
        if (i_fixed && book_[j].fixed != 0) return;  // bumps never meet
        const double b = dot3(dr, dv);
        if (b >= 0.0) return;
        const double sigma = ri + P_[j].r;
        const double cc = dot3(dr, dr) - sigma * sigma;
        double t;
        if (cc <= 0.0) {
            t = 0.0;  // touching or overlapping and approaching: collide now
        } else {
            const double aa = dot3(dv, dv);
            const double disc = b * b - aa * cc;
            if (disc <= 0.0) return;
            t = cc / (-b + std::sqrt(disc));
        }
        if (t < best || (t == best && partner >= 0 && j < partner)) {
            best = t;
            partner = j;
            partner_count = book_[j].count;
        }
    };
    const std::int32_t* ci = book_[i].cell;
    bool interior = !has_bumps_;
    for (int a = 0; a < p_.dim; ++a) interior = interior && ci[a] >= 1 && ci[a] + 1 < ncell_[a];
    if (interior) {
        // the common case, batched: gather the candidates of the neighbouring cells (no image
        // shifts), compute their collision times together (pair_times), keep the earliest
        constexpr int kBatch = 64;
        std::int32_t js[kBatch];
        double ts[kBatch];
        int nb = 0;
        const std::int32_t stored = partner;
        auto flush = [&]() {
            if (nb == 0) return;
            pair_times(gravity_, P_.data(), js, nb, xi, vi, ri, time_, p_.gravity, ts);
            for (int q = 0; q < nb; ++q) {
                const double t = ts[q];
                const std::int32_t j = js[q];
                if (t < best || (t == best && t < kInf && partner >= 0 && j < partner)) {
                    best = t;
                    partner = j;
                }
            }
            nb = 0;
        };
        const std::int64_t base = cell_index(ci);
        const int list = only_axis < 0 ? 0 : 1 + 2 * only_axis + (dir > 0);
        const std::int64_t* off = nb_off_[list];
        const int nk = n_nb_[list];
        // all cell heads first: independent loads that overlap, where walking cell by cell
        // would wait for each (a mostly empty cell's test mispredicts on the loaded value)
        std::int32_t heads[27];
        for (int k = 0; k < nk; ++k) heads[k] = head_[base + off[k]];
        for (int k = 0; k < nk; ++k)
            for (std::int32_t j = heads[k]; j >= 0; j = next_[j]) {
                if (j == i) continue;
                // issued while the lists are walked, the misses on the records overlap
                __builtin_prefetch(&P_[j]);
                js[nb++] = j;
                if (nb == kBatch) flush();
            }
        flush();
        // the partner's collision counter once, at the end (a miss per candidate otherwise)
        if (partner >= 0 && partner != stored) partner_count = book_[partner].count;
    } else {
        // bumps, or a row next to a Lees–Edwards boundary: one pair at a time. The candidates
        // are extrapolated along their flights as in pair_times (g = 0 without gravity gives
        // the same numbers as straight lines).
        const double* g = p_.gravity;
        std::int32_t kind = kNone;
        const double horizon = gravity_ && has_bumps_ ? next_boundary(i, kind) : kInf;
        const double minus_g[3] = {-g[0], -g[1], -g[2]};
        for_neighbours(i, only_axis, dir, [&](std::int32_t j, const double* sh, const double* vs) {
            const Particle& pj = P_[j];
            const double dtj = time_ - pj.t;
            double dr[3], dv[3];
            // a static bump: the relative motion is a parabola
            if (gravity_ && book_[j].fixed != 0) {
                for (int a = 0; a < 3; ++a) {
                    dr[a] = pj.x[a] + pj.v[a] * dtj + (sh ? sh[a] : 0.0) - xi[a];
                    dv[a] = pj.v[a] + (sh ? vs[a] : 0.0) - vi[a];
                }
                const double t = bump_contact_time(dr, dv, minus_g, ri + pj.r,
                                                   std::min(horizon, best));
                if (t < best || (t == best && partner >= 0 && j < partner)) {
                    best = t;
                    partner = j;
                    partner_count = book_[j].count;
                }
                return;
            }
            for (int a = 0; a < 3; ++a) {
                dr[a] = pj.x[a] + (pj.v[a] + 0.5 * g[a] * dtj) * dtj - xi[a];
                dv[a] = pj.v[a] + g[a] * dtj - vi[a];
            }
            if (sh != nullptr)
                for (int a = 0; a < 3; ++a) {
                    dr[a] += sh[a];
                    dv[a] += vs[a];
                }
            consider(j, dr, dv);
        });
    }
    if (partner >= 0) {
        book_[i].co_t = time_ + best;
        book_[i].co_partner = partner;
        book_[i].co_count = partner_count;
    }
}

double EventDriven::wall_time(std::int32_t i, int side) const {
    const Wall& w = p_.wall[side];
    const double y = P_[i].x[1], vy = P_[i].v[1], r = P_[i].r;
    const double yw = w.position(time_);
    if (side == 0) return first_hit(-(y - r - yw), -(vy - w.vn), -p_.gravity[1]);
    return first_hit(-(yw - y - r), vy - w.vn, p_.gravity[1]);
}

// i's event: the earliest of its cell crossings, wall collisions and collision candidate.
void EventDriven::schedule(std::int32_t i) {
    std::int32_t kind = kNone;
    const double best = next_boundary(i, kind);
    const double other = time_ + best;
    if (book_[i].co_partner >= 0 && book_[i].co_t <= other) {
        node_at(book_[i].pos_in_heap).t = book_[i].co_t;
        book_[i].ev_partner = book_[i].co_partner;
    } else {
        node_at(book_[i].pos_in_heap).t = other;
        book_[i].ev_partner = kind;
    }
}

// Time from now until i (synchronised) leaves its cell or meets a wall, and which.
double EventDriven::next_boundary(std::int32_t i, std::int32_t& kind) const {
    const double* xi = P_[i].x;
    const double* vi = P_[i].v;
    const double* g = grav(i);
    const std::int32_t* ci = book_[i].cell;
    double best = kInf;
    kind = kNone;
    for (int a = 0; a < p_.dim; ++a) {
        const bool open = a == 1 && !p_.periodic_y;
        const double lo = org_[a] + ci[a] * cw_[a];
        const double hi = ci[a] + 1 == ncell_[a] && !open ? p_.box[a] : lo + cw_[a];
        if (g[a] == 0.0) {  // straight flight: one boundary ahead
            if (vi[a] == 0.0) continue;
            const bool up = vi[a] > 0.0;
            if (open && ci[a] == (up ? ncell_[a] - 1 : 0)) continue;
            const double t = std::max(0.0, ((up ? hi : lo) - xi[a]) / vi[a]);
            if (t < best) {
                best = t;
                kind = up ? -(a + 1) : -(a + 4);
            }
            continue;
        }
        if (!(open && ci[a] + 1 == ncell_[a])) {
            const double t = first_hit(xi[a] - hi, vi[a], g[a]);
            if (t < best) {
                best = t;
                kind = -(a + 1);
            }
        }
        if (!(open && ci[a] == 0)) {
            const double t = first_hit(lo - xi[a], -vi[a], -g[a]);
            if (t < best) {
                best = t;
                kind = -(a + 4);
            }
        }
    }
    for (int s = 0; s < 2; ++s) {
        if (!p_.wall[s].present || book_[i].fixed != 0) continue;
        const double t = wall_time(i, s);
        if (t < best) {
            best = t;
            kind = s == 0 ? kLowerWall : kUpperWall;
        }
    }
    return best;
}

void EventDriven::predict(std::int32_t i) {
    advance(i, time_);
    book_[i].co_t = kInf;
    book_[i].co_partner = -1;
    book_[i].co_count = 0;
    if (!(gravity_ && book_[i].fixed != 0)) scan(i, -1, 0);  // static bumps under gravity: none
    schedule(i);
}

// After a crossing along `axis` in direction `dir`: the collision candidate found so far is
// still the earliest among the partners scanned before (whose trajectories are unchanged, or
// they re-predicted themselves and scanned i), so only the newly adjacent cell layer is
// scanned. A stale candidate (partner collided since) forces a full prediction, as does a
// row next to a Lees–Edwards boundary (its image cells slide).
void EventDriven::predict_crossed(std::int32_t i, int axis, int dir) {
    const std::int32_t p = book_[i].co_partner;
    // a full scan also when bumps meet falling particles: their contact times were only
    // searched up to this crossing
    if ((p >= 0 && book_[p].count != book_[i].co_count) || le_row(i) || (gravity_ && has_bumps_)) {
        predict(i);
        return;
    }
    scan(i, axis, dir);
    schedule(i);
}

void EventDriven::predict_all() {
    for (std::int32_t i = 0; i < static_cast<std::int32_t>(n_); ++i) predict(i);
}

// Re-predict the particles of the two rows next to the Lees–Edwards boundary.
void EventDriven::predict_rows() {
    const int rows[2] = {0, ncell_[1] - 1};
    for (int k = 0; k < (ncell_[1] > 1 ? 2 : 1); ++k)
        for (int cz = 0; cz < ncell_[2]; ++cz)
            for (int cx = 0; cx < ncell_[0]; ++cx) {
                const std::int32_t c[3] = {cx, rows[k], cz};
                for (std::int32_t i = head_[cell_index(c)]; i >= 0; i = next_[i]) {
                    predict(i);
                    heap_update(i);
                }
            }
}

void EventDriven::schedule_system() {
    book_[n_].ev_partner = kReshuffle;
    node_at(book_[n_].pos_in_heap).t =
        p_.shear_rate != 0.0 ? le_t_ + cw_[0] / (p_.shear_rate * p_.box[1]) : kInf;
}

void EventDriven::heap_up(std::int64_t k) {
    const Node node = node_at(k);
    while (k > 0) {
        const std::int64_t parent = (k - 1) / kArity;
        if (!less(node, node_at(parent))) break;
        node_at(k) = node_at(parent);
        book_[node_at(k).i].pos_in_heap = static_cast<std::int32_t>(k);
        k = parent;
    }
    node_at(k) = node;
    book_[node.i].pos_in_heap = static_cast<std::int32_t>(k);
}

void EventDriven::heap_down(std::int64_t k) {
    const Node node = node_at(k);
    const std::int64_t n = n_ + 1;
    while (true) {
        const std::int64_t first = kArity * k + 1;
        if (first >= n) break;
        const std::int64_t last = std::min(first + kArity, n);
        // the next level's candidate lines (the children of these children): their misses
        // overlap with this level's comparisons
        const std::int64_t next_first = kArity * first + 1;
        for (std::int64_t c = 0; c < kArity && next_first + kArity * c < n; ++c)
            __builtin_prefetch(&node_at(next_first + kArity * c));
        std::int64_t child = first;
        for (std::int64_t c = first + 1; c < last; ++c)
            if (less(node_at(c), node_at(child))) child = c;
        if (!less(node_at(child), node)) break;
        node_at(k) = node_at(child);
        book_[node_at(k).i].pos_in_heap = static_cast<std::int32_t>(k);
        k = child;
    }
    node_at(k) = node;
    book_[node.i].pos_in_heap = static_cast<std::int32_t>(k);
}

// The node of i already holds its new time (schedule writes it): restore the heap order.
void EventDriven::heap_update(std::int32_t i) {
    const std::int64_t k = book_[i].pos_in_heap;
    heap_up(k);
    heap_down(book_[i].pos_in_heap);
}

// Re-establish the heap order of the node array (node times are current).
void EventDriven::heap_build() {
    for (std::int64_t k = n_ > 0 ? (n_ - 1) / kArity : -1; k >= 0; --k) heap_down(k);
}

// Collisional stress per bin along y: r_ij ⊗ J_i shared among the bins the branch r_i → r_j
// crosses, in proportion to the length inside each (a branch in one plane y = const goes to
// its bin). Periodic y: bins wrap; otherwise parts outside the bins are dropped.
void EventDriven::add_stress(double yi, double yj, const double dr[3], const double J[3]) {
    const std::int64_t nb = p_.stress_bins;
    if (nb == 0) return;
    double t[9];
    for (int a = 0; a < 3; ++a)
        for (int b = 0; b < 3; ++b) t[3 * a + b] = -dr[a] * J[b];
    const double w = p_.stress_width, lo = p_.stress_lo;
    const double ya = std::min(yi, yj), yb = std::max(yi, yj);
    auto add = [&](std::int64_t bin, double frac) {
        if (p_.periodic_y) bin = ((bin % nb) + nb) % nb;
        if (bin < 0 || bin >= nb || frac <= 0.0) return;
        double* s = &stress_[9 * bin];
        for (int k = 0; k < 9; ++k) s[k] += frac * t[k];
    };
    // bin numbers, clamped before the integer conversion: along a bounded y to one bin beyond
    // each end (dropped), along a periodic y to one turn of the bins after the first
    double f0 = std::floor((ya - lo) / w), f1 = std::floor((yb - lo) / w);
    const double big = 1e15, nbd = static_cast<double>(nb);
    if (p_.periodic_y) {
        f0 = std::clamp(f0, -big, big);
        f1 = std::clamp(f1, f0, f0 + nbd);
    } else {
        f0 = std::clamp(f0, -1.0, nbd);
        f1 = std::clamp(f1, -1.0, nbd);
    }
    const auto b0 = static_cast<std::int64_t>(f0), b1 = static_cast<std::int64_t>(f1);
    if (b0 == b1 || yb == ya) {
        add(b0, 1.0);
        return;
    }
    const double len = yb - ya;
    for (std::int64_t b = b0; b <= b1; ++b) {
        const double s0 = std::max(ya, lo + b * w), s1 = std::min(yb, lo + (b + 1) * w);
        add(b, (s1 - s0) / len);
    }
}

void EventDriven::log_collision(int kind, std::int32_t i, std::int32_t j, const double point[3],
                                const double n[3], const double branch[3], const double J[3],
                                const double v[3], const double g[3]) {
    ++log_seen_;
    if (p_.log_every <= 0 || log_seen_ % p_.log_every != 0 ||
        static_cast<std::int64_t>(log_.size()) >= p_.log_capacity)
        return;
    LogRecord r{};
    r.time = time_;
    r.kind = kind;
    r.i = order_[i];
    r.j = j >= 0 ? order_[j] : -1;
    for (int a = 0; a < 3; ++a) {
        r.point[a] = point[a];
        r.normal[a] = n[a];
        r.branch[a] = branch[a];
        r.impulse[a] = J[a];
        r.velocity[a] = v[a];
        r.slip[a] = g[a];
    }
    log_.push_back(r);
}

std::vector<LogRecord> EventDriven::take_log() {
    std::vector<LogRecord> out;
    out.swap(log_);
    return out;
}

void EventDriven::process_collision(std::int32_t i, std::int32_t j) {
    if (book_[i].fixed != 0 || book_[j].fixed != 0) {
        process_bump(book_[i].fixed != 0 ? j : i, book_[i].fixed != 0 ? i : j);
        return;
    }
    advance(i, time_);
    advance(j, time_);
    double dr[3], vs[3];
    separation(i, j, dr, vs);
    const double dist = std::sqrt(dot3(dr, dr));
    double n[3] = {dr[0] / dist, dr[1] / dist, dr[2] / dist};
    double* vi = P_[i].v;
    double* vj = P_[j].v;
    double* wi = spin_[i].w;
    double* wj = spin_[j].w;
    const double ri = P_[i].r, rj = P_[j].r, K = p_.inertia_k;
    double vji[3];  // j's image velocity
    for (int a = 0; a < 3; ++a) vji[a] = vj[a] + vs[a];
    // pre-collision contact-point velocity g = vi - vj + (ri wi + rj wj) x n
    double s[3], sxn[3], g[3], vrel[3];
    for (int a = 0; a < 3; ++a) s[a] = ri * wi[a] + rj * wj[a];
    cross3(s, n, sxn);
    for (int a = 0; a < 3; ++a) {
        vrel[a] = vi[a] - vji[a];
        g[a] = vrel[a] + sxn[a];
    }
    const double gn = dot3(g, n);
    double gt2 = 0.0;
    for (int a = 0; a < 3; ++a) gt2 += (g[a] - gn * n[a]) * (g[a] - gn * n[a]);
    double e, beta;
    if (p_.tc > 0.0 && (time_ - book_[i].last < p_.tc || time_ - book_[j].last < p_.tc)) {
        e = 1.0;
        beta = -1.0;
        ++tc_elastic_;
    } else {
        e = p_.pair.restitution(std::max(gn, 0.0));
        beta = p_.pair.beta_for(e, K, std::max(gn, 0.0), std::sqrt(gt2));
    }
    book_[i].last = book_[j].last = time_;
    auto energy = [&]() {
        return 0.5 * spin_[i].m * (dot3(vi, vi) + K * ri * ri * dot3(wi, wi)) +
               0.5 * spin_[j].m * (dot3(vji, vji) + K * rj * rj * dot3(wj, wj));
    };
    const double before = energy();
    double J[3];
    collide(n, ri, rj, 1.0 / spin_[i].m, 1.0 / spin_[j].m, K, e, beta, vi, vji, wi, wj, J);
    dissipated_ += before - energy();
    for (int a = 0; a < 3; ++a) vj[a] = vji[a] - vs[a];
    for (int a = 0; a < 3; ++a)
        for (int b = 0; b < 3; ++b) virial_[3 * a + b] += -dr[a] * J[b];
    add_stress(P_[i].x[1], P_[i].x[1] + dr[1], dr, J);
    if (p_.log_every > 0) {
        double point[3];
        for (int a = 0; a < 3; ++a) point[a] = P_[i].x[a] + n[a] * ri;
        log_collision(0, i, j, point, n, dr, J, vrel, g);
    }
    ++book_[i].count;
    ++book_[j].count;
    ++collisions_;
    predict(i);
    heap_update(i);
    predict(j);
    heap_update(j);
}

// A mobile particle i meets bump b of a bumpy wall: the wall's rule with m* = m_i (the bump
// keeps its velocity, the wall's); the impulse and work count for that wall.
void EventDriven::process_bump(std::int32_t i, std::int32_t b) {
    advance(i, time_);
    advance(b, time_);
    double dr[3], vs[3];
    separation(i, b, dr, vs);
    const double dist = std::sqrt(dot3(dr, dr));
    const double n[3] = {dr[0] / dist, dr[1] / dist, dr[2] / dist};
    double ub[3], vrel[3];
    for (int a = 0; a < 3; ++a) {
        ub[a] = P_[b].v[a] + vs[a];
        vrel[a] = P_[i].v[a] - ub[a];
    }
    const double sigma = P_[i].r + P_[b].r;
    if (dot3(vrel, n) > 0.0) {
        body_contact(i, book_[b].fixed - 1, n, ub, true, b);
    } else if (dot3(p_.gravity, n) > 0.0 && dist - sigma <= 1e-9 * sigma) {
        // touching, not approaching, pressed on by gravity (resting or sliding on the bump: the
        // contact search returns the turning point): the minimum rebound alone, as on a flat
        // wall, so the particle hops instead of meeting the bump again at the same time
        body_contact(i, book_[b].fixed - 1, n, ub, false, b, false);
    } else {
        ++invalid_;  // not approaching (round-off)
    }
    predict(i);
    heap_update(i);
    predict(b);
    heap_update(b);
}

// Minimum rebound when gravity presses the particle onto the body it hit (n from the particle
// to the body, u the body's velocity): it leaves at least at ½ t_r (g·n), t_r = t_c (1e-8
// without the TC model), so it hops with a period of at least t_r instead of colliding
// infinitely often. Adds to the velocity v and the impulse J.
void EventDriven::rebound_floor(const double n[3], const double u[3], double m, double v[3],
                                double J[3]) {
    const double gnorm = dot3(p_.gravity, n);
    if (!(gnorm > 0.0)) return;
    const double rest = p_.tc > 0.0 ? p_.tc : 1e-8;
    const double vmin = 0.5 * rest * gnorm;
    double out[3];
    for (int a = 0; a < 3; ++a) out[a] = v[a] - u[a];
    const double vout = -dot3(out, n);  // > 0: leaving
    if (vout >= vmin) return;
    const double dv = vout - vmin;
    for (int a = 0; a < 3; ++a) {
        v[a] += dv * n[a];
        J[a] += m * dv * n[a];
    }
    ++resting_;
}

// A wall is a body of infinite mass moving with (u_x, v_n, u_z).
void EventDriven::process_wall(std::int32_t i, int side) {
    advance(i, time_);
    const Wall& w = p_.wall[side];
    const double n[3] = {0.0, side == 0 ? -1.0 : 1.0, 0.0};  // particle -> wall
    const double uw[3] = {w.u[0], w.vn, p_.dim == 3 ? w.u[2] : 0.0};
    body_contact(i, side, n, uw, false, -1);
    predict(i);
    heap_update(i);
}

// Particle i meets a body of infinite mass moving with u (wall `side`, or a bump of it:
// `partner`, -1 for the wall; n from the particle to the body): the wall's rule with m* = m
// (Campbell's no-slip rule: the centre takes the body's tangential velocity, the spin is
// unchanged, the normal velocity is reversed with e_w), the TC model when `tc_model` (bumps;
// walls have the minimum rebound instead), the minimum rebound under gravity; the impulse and
// work count for the wall, the contact's stress goes to the bins along the branch r n (as the
// LAMMPS contact stress, so the bins next to a wall carry its stress), energy is booked in
// the body's frame. apply_rule = false (a particle resting on a bump, touching but not
// approaching): the minimum rebound alone. The caller re-predicts.
void EventDriven::body_contact(std::int32_t i, int side, const double n[3], const double u[3],
                               bool tc_model, std::int32_t partner, bool apply_rule) {
    const Rule& rule = p_.wall[side].rule;
    double* v = P_[i].v;
    double* om = spin_[i].w;
    const double r = P_[i].r, m = spin_[i].m, K = p_.inertia_k;
    double vrel[3], rw[3], rwxn[3], g[3];
    for (int a = 0; a < 3; ++a) {
        vrel[a] = v[a] - u[a];
        rw[a] = r * om[a];
    }
    cross3(rw, n, rwxn);
    for (int a = 0; a < 3; ++a) g[a] = vrel[a] + rwxn[a];
    const double g_n = dot3(g, n);
    const double gn = std::max(g_n, 0.0);
    double gt2 = 0.0;
    for (int a = 0; a < 3; ++a) gt2 += (g[a] - g_n * n[a]) * (g[a] - g_n * n[a]);
    const bool elastic = apply_rule && tc_model && p_.tc > 0.0 && time_ - book_[i].last < p_.tc;
    if (elastic) ++tc_elastic_;
    const double e = elastic ? 1.0 : rule.restitution(gn);
    auto energy = [&]() {  // in the body's frame
        double du[3];
        for (int a = 0; a < 3; ++a) du[a] = v[a] - u[a];
        return 0.5 * m * (dot3(du, du) + K * r * r * dot3(om, om));
    };
    const double before = energy();
    double J[3] = {0.0, 0.0, 0.0};
    if (!apply_rule) {
        // the minimum rebound below only
    } else if (rule.tangential == Rule::kNoSlip) {  // walls only (bumps refuse it)
        const double vn = dot3(vrel, n);
        for (int a = 0; a < 3; ++a) {
            const double new_v = u[a] - e * vn * n[a];
            J[a] = m * (new_v - v[a]);
            v[a] = new_v;
        }
    } else {
        const double beta = elastic ? -1.0 : rule.beta_for(e, K, gn, std::sqrt(gt2));
        double body[3] = {u[0], u[1], u[2]}, unused[3] = {0.0, 0.0, 0.0};
        collide(n, r, 0.0, 1.0 / m, 0.0, K, e, beta, v, body, om, unused, J);
    }
    rebound_floor(n, u, m, v, J);
    dissipated_ += before - energy();
    wall_work_[side] += dot3(J, u);
    double branch[3], point[3];
    for (int a = 0; a < 3; ++a) {
        branch[a] = r * n[a];
        point[a] = P_[i].x[a] + branch[a];
        wall_impulse_[side][a] += J[a];
    }
    add_stress(P_[i].x[1], point[1], branch, J);
    if (p_.log_every > 0) log_collision(side + 1, i, partner, point, n, branch, J, vrel, g);
    book_[i].last = time_;
    ++book_[i].count;  // never the bump's: its trajectory does not change
    ++wall_collisions_;
}

void EventDriven::process_crossing(std::int32_t i, int code) {
    advance(i, time_);
    const int axis = code >= -3 ? -code - 1 : -code - 4;
    const int dir = code >= -3 ? 1 : -1;
    remove_cell(i);
    std::int32_t& c = book_[i].cell[axis];
    bool wrapped = false;
    c += dir;
    if (c == ncell_[axis] || c < 0) {  // periodic axes only (open rows have no crossing out)
        c = c < 0 ? ncell_[axis] - 1 : 0;
        P_[i].x[axis] -= dir * p_.box[axis];
        wrapped = true;
    }
    if (wrapped && axis == 1 && p_.shear_rate != 0.0) {
        // through a Lees–Edwards boundary: take the image's x position and velocity
        const double L = p_.box[0];
        double x = P_[i].x[0] - dir * le_delta(time_);
        x -= L * std::floor(x / L);
        if (x >= L) x -= L;
        P_[i].x[0] = x;
        P_[i].v[0] -= dir * p_.shear_rate * p_.box[1];
        book_[i].cell[0] = cell_of(x, 0);
    }
    insert_cell(i);
    ++crossings_;
    if (wrapped && axis == 1 && p_.shear_rate != 0.0)
        predict(i);
    else
        predict_crossed(i, axis, dir);
    heap_update(i);
}

// The Lees–Edwards offset has moved by one cell width: re-scan the rows next to the boundary.
void EventDriven::process_reshuffle() {
    le_cell_ = (le_cell_ + 1) % ncell_[0];
    le_t_ = time_;
    schedule_system();
    heap_update(static_cast<std::int32_t>(n_));
    predict_rows();
}

bool EventDriven::advance_to(double t, std::int64_t max_events, std::int64_t stop_collisions) {
    if (!(t >= time_)) throw std::invalid_argument("advance_to: time must not decrease");
    if (!std::isfinite(t)) throw std::invalid_argument("advance_to: time must be finite");
    // the budget counts stale predictions too: a loop of them must not run for ever
    const std::int64_t start = events() + invalid_;
    bool reached = true;
    while (true) {
        if ((max_events > 0 && events() + invalid_ - start >= max_events) ||
            (stop_collisions > 0 && collisions_ >= stop_collisions)) {
            reached = false;
            break;
        }
        const std::int32_t i = node_at(0).i;
        const double et = node_at(0).t;
        if (!(et <= t)) break;
        if (events() - sorted_at_ >= kSortEvery * n_) {
            for (std::int32_t k = 0; k < static_cast<std::int32_t>(n_); ++k) advance(k, time_);
            reorder();
            continue;
        }
        time_ = et;
        if (i == static_cast<std::int32_t>(n_)) {
            process_reshuffle();
            continue;
        }
        const std::int32_t p = book_[i].ev_partner;
        if (p >= 0) {
            if (book_[p].count != book_[i].co_count) {  // the event is i's collision candidate
                ++invalid_;
                predict(i);
                heap_update(i);
            } else {
                process_collision(i, p);
            }
        } else if (p == kLowerWall || p == kUpperWall) {
            process_wall(i, p == kLowerWall ? 0 : 1);
        } else if (p >= -6) {
            process_crossing(i, p);
        } else {
            throw std::logic_error("edmd: corrupt event queue");
        }
    }
    if (reached) time_ = t;
    for (std::int32_t i = 0; i < static_cast<std::int32_t>(n_); ++i) advance(i, time_);
    return reached;
}

// perm <- the indices 0..N-1 ordered by (Morton key of the cell, index): keys computed once.
void EventDriven::sort_by_cell(std::vector<std::int32_t>& perm) const {
    const std::size_t N = static_cast<std::size_t>(n_);
    std::vector<std::pair<std::uint64_t, std::int32_t>> key(N);
    for (std::size_t i = 0; i < N; ++i)
        key[i] = {morton(book_[i].cell), static_cast<std::int32_t>(i)};
    std::sort(key.begin(), key.end());
    perm.resize(N);
    for (std::size_t k = 0; k < N; ++k) perm[k] = key[k].second;
}

// Store the particles in cell order again (they drift apart in memory as they move, and the
// neighbour scans then miss the cache). Called every kSortEvery · N events;
// indices change, so every stored index is remapped (the event order (time, index) may then
// break exact ties differently: deterministic, since the points are part of the state).
// The particles are synchronised first (scheduled events stay valid).
void EventDriven::reorder() {
    const std::size_t N = static_cast<std::size_t>(n_);
    std::vector<std::int32_t> perm(N), inv(N);
    for (std::size_t i = 0; i < N; ++i) perm[i] = static_cast<std::int32_t>(i);
    sort_by_cell(perm);
    for (std::size_t k = 0; k < N; ++k) inv[static_cast<std::size_t>(perm[k])] =
        static_cast<std::int32_t>(k);
    std::vector<char> done;
    auto permute = [&](auto& v, std::size_t width) { permute_rows(v, width, perm, done); };
    permute(P_, 1);
    permute(order_, 1);
    permute(spin_, 1);
    {
        // the system slot n_ stays where it is: permute the first N entries only
        const Book sys = book_[N];
        book_.pop_back();
        permute(book_, 1);
        book_.push_back(sys);
    }
    for (std::int64_t k = 0; k <= n_; ++k) {
        Node& node = node_at(k);
        if (node.i < static_cast<std::int32_t>(n_)) node.i = inv[static_cast<std::size_t>(node.i)];
        book_[node.i].pos_in_heap = static_cast<std::int32_t>(k);
    }
    for (std::size_t k = 0; k < N; ++k) {
        Book& b = book_[k];
        if (b.co_partner >= 0) b.co_partner = inv[static_cast<std::size_t>(b.co_partner)];
        if (b.ev_partner >= 0) b.ev_partner = inv[static_cast<std::size_t>(b.ev_partner)];
    }
    build_cells();
    heap_build();
    sorted_at_ = events();
}

void EventDriven::set_wall(int side, double y, double vn, double ux, double uz) {
    if (side < 0 || side > 1 || !p_.wall[side].present)
        throw std::invalid_argument("set_wall: no such wall");
    if (!std::isfinite(y) || !std::isfinite(vn) || !std::isfinite(ux) || !std::isfinite(uz))
        throw std::invalid_argument("set_wall: values must be finite");
    Wall& w = p_.wall[side];
    w.y0 = y;
    w.t0 = time_;
    w.vn = vn;
    w.u[0] = ux;
    w.u[2] = p_.dim == 3 ? uz : 0.0;
    for (std::int32_t i = 0; i < static_cast<std::int32_t>(n_); ++i) {
        advance(i, time_);
        schedule(i);
    }
    heap_build();
}

void EventDriven::check_stress_bins(double lo, double width, double n, const char* who) {
    if (!(n >= 0.0 && n <= kMaxStressBins && n == std::floor(n)) ||
        (n > 0.0 && !(width > 0.0 && std::isfinite(width))) || !std::isfinite(lo))
        throw std::invalid_argument(std::string(who) +
                                    ": need 0 to 10^7 stress bins of finite positive width "
                                    "from a finite lower edge");
}

void EventDriven::set_stress_bins(double lo, double width, std::int64_t n) {
    check_stress_bins(lo, width, static_cast<double>(n), "set_stress_bins");
    p_.stress_lo = lo;
    p_.stress_width = width;
    p_.stress_bins = n;
    stress_.assign(static_cast<std::size_t>(9 * n), 0.0);
}

// Shrinking x affinely must not make touching pairs overlap: the factor is limited to the
// smallest one every neighbouring pair allows (f² dx² + dy² + dz² >= σ²), with a margin of
// 1e-9 d; a jammed packing thus keeps its width. Returns the factor applied.
double EventDriven::scale_width(double factor) {
    if (!(factor > 0.0) || !std::isfinite(factor))
        throw std::invalid_argument("scale_width: factor must be positive");
    if (p_.shear_rate != 0.0) throw std::invalid_argument("scale_width: not with Lees-Edwards");
    for (std::int32_t i = 0; i < static_cast<std::int32_t>(n_); ++i) advance(i, time_);
    if (factor < 1.0) {
        double f_min = 0.0;
        for (std::int32_t i = 0; i < static_cast<std::int32_t>(n_); ++i) {
            for_neighbours(i, -1, 0, [&](std::int32_t j, const double* sh, const double*) {
                if (j <= i || (book_[i].fixed != 0 && book_[j].fixed != 0)) return;
                double dr[3];
                for (int a = 0; a < 3; ++a) dr[a] = P_[j].x[a] + (sh ? sh[a] : 0.0) - P_[i].x[a];
                const double sigma = P_[i].r + P_[j].r + 1e-9;
                const double need = sigma * sigma - dr[1] * dr[1] - dr[2] * dr[2];
                if (need > 0.0 && dr[0] != 0.0)
                    f_min = std::max(f_min, std::sqrt(need) / std::fabs(dr[0]));
            });
        }
        factor = std::min(1.0, std::max(factor, f_min));
    }
    if (factor == 1.0) return 1.0;
    for (std::int32_t i = 0; i < static_cast<std::int32_t>(n_); ++i) P_[i].x[0] *= factor;
    p_.box[0] *= factor;
    setup_grid();  // the cell widths may change along every axis (the cell budget is global)
    for (std::int32_t i = 0; i < static_cast<std::int32_t>(n_); ++i) {
        double& x = P_[i].x[0];
        x -= p_.box[0] * std::floor(x / p_.box[0]);
        if (x >= p_.box[0]) x -= p_.box[0];
        for (int a = 0; a < p_.dim; ++a) book_[i].cell[a] = cell_of(P_[i].x[a], a);
    }
    build_cells();
    predict_all();
    heap_build();
    return factor;
}

void EventDriven::positions(double* out) const {
    for (std::int64_t i = 0; i < n_; ++i) {
        const std::int64_t o = order_[i];
        double x[3], v[3];
        state_at(static_cast<std::int32_t>(i), time_, x, v);
        for (int a = 0; a < p_.dim; ++a) {
            const double L = p_.box[a];
            double xa = x[a];
            if (a == 1 && p_.shear_rate != 0.0) {
                xa = std::clamp(xa, 0.0, std::nextafter(L, 0.0));  // wrapping needs the offset
            } else if (a != 1 || p_.periodic_y) {
                xa -= L * std::floor(xa / L);
                if (xa >= L) xa -= L;
            }
            out[o * p_.dim + a] = xa;
        }
    }
}

void EventDriven::velocities(double* out) const {
    for (std::int64_t i = 0; i < n_; ++i) {
        double x[3], v[3];
        state_at(static_cast<std::int32_t>(i), time_, x, v);
        for (int a = 0; a < p_.dim; ++a) out[order_[i] * p_.dim + a] = v[a];
    }
}

void EventDriven::angular_velocities(double* out) const {
    for (std::int64_t i = 0; i < n_; ++i) {
        const std::int64_t o = order_[i];
        if (p_.dim == 2)
            out[o] = spin_[i].w[2];
        else
            for (int a = 0; a < 3; ++a) out[3 * o + a] = spin_[i].w[a];
    }
}

double EventDriven::kinetic_energy() const {
    double e = 0.0;
    for (std::int64_t i = 0; i < n_; ++i) {
        double x[3], v[3];
        if (book_[i].fixed != 0) continue;
        state_at(static_cast<std::int32_t>(i), time_, x, v);
        e += 0.5 * spin_[i].m * dot3(v, v);
    }
    return e;
}

double EventDriven::rotational_energy() const {
    double e = 0.0;
    for (std::int64_t i = 0; i < n_; ++i)
        if (book_[i].fixed == 0)
            e += 0.5 * p_.inertia_k * spin_[i].m * P_[i].r * P_[i].r * dot3(spin_[i].w, spin_[i].w);
    return e;
}

EventDriven::State EventDriven::get_state() const {
    const std::size_t N = static_cast<std::size_t>(n_);
    State s;
    s.pos.resize(3 * n_);
    s.vel.resize(3 * n_);
    for (std::int64_t i = 0; i < n_; ++i) {
        double x[3], v[3];
        state_at(static_cast<std::int32_t>(i), time_, x, v);
        for (int a = 0; a < 3; ++a) {
            s.pos[3 * i + a] = x[a];
            s.vel[3 * i + a] = v[a];
        }
    }
    s.omega.resize(3 * N);
    for (std::size_t i = 0; i < N; ++i)
        for (int a = 0; a < 3; ++a) s.omega[3 * i + a] = spin_[i].w[a];
    s.last.resize(N);
    s.count.resize(N);
    s.cell.resize(3 * N);
    s.co_time.resize(N);
    s.co_partner.resize(N);
    s.co_count.resize(N);
    s.ev_partner.resize(N + 1);
    s.ev_time.resize(N + 1);
    s.ev_count.assign(N + 1, 0);
    for (std::size_t i = 0; i <= N; ++i) {
        const Book& b = book_[i];
        s.ev_partner[i] = b.ev_partner;
        s.ev_time[i] = node_at(b.pos_in_heap).t;
        if (i == N) break;  // the system slot: its event only
        if (b.ev_partner >= 0) s.ev_count[i] = b.co_count;
        s.last[i] = b.last;
        s.count[i] = b.count;
        for (int a = 0; a < 3; ++a) s.cell[3 * i + a] = b.cell[a];
        s.co_time[i] = b.co_t;
        s.co_partner[i] = b.co_partner;
        s.co_count[i] = b.co_count;
    }
    s.stress = stress_;
    s.scalars = {time_, dissipated_, gravity_work_, p_.box[0], le_t_,
                 static_cast<double>(le_cell_)};
    for (int k = 0; k < 2; ++k) {
        const Wall& w = p_.wall[k];
        s.scalars.insert(s.scalars.end(), {w.y0, w.t0, w.vn, w.u[0], w.u[2]});
    }
    for (int k = 0; k < 2; ++k)
        s.scalars.insert(s.scalars.end(), wall_impulse_[k], wall_impulse_[k] + 3);
    s.scalars.insert(s.scalars.end(), {wall_work_[0], wall_work_[1]});
    s.scalars.insert(s.scalars.end(), virial_, virial_ + 9);
    s.scalars.insert(s.scalars.end(), {p_.stress_lo, p_.stress_width,
                                       static_cast<double>(p_.stress_bins)});
    s.counters = {collisions_, crossings_, invalid_, tc_elastic_, resting_, wall_collisions_,
                  log_seen_, sorted_at_};
    s.order = order_;
    return s;
}

// Everything is checked before anything changes: a rejected state leaves the engine as it was.
void EventDriven::set_state(const State& s) {
    const std::size_t N = static_cast<std::size_t>(n_);
    if (s.pos.size() != 3 * N || s.vel.size() != 3 * N || s.omega.size() != 3 * N ||
        s.last.size() != N || s.count.size() != N || s.cell.size() != 3 * N ||
        s.scalars.size() != 36 || s.counters.size() != 8 || s.order.size() != N)
        throw std::invalid_argument("set_state: array sizes do not match this system");
    for (double x : s.scalars)
        if (!std::isfinite(x)) throw std::invalid_argument("set_state: non-finite scalar");
    check_stress_bins(s.scalars[33], s.scalars[34], s.scalars[35], "set_state");
    if (s.stress.size() != 9 * static_cast<std::size_t>(s.scalars[35]))
        throw std::invalid_argument("set_state: stress sums do not match the stress bins");
    for (std::size_t k = 0; k < 3 * N; ++k)
        if (!std::isfinite(s.pos[k]) || !std::isfinite(s.vel[k]) || !std::isfinite(s.omega[k]))
            throw std::invalid_argument("set_state: non-finite position or velocity");
    for (std::size_t i = 0; i < N; ++i)
        if (std::isnan(s.last[i]) || s.last[i] == kInf)
            throw std::invalid_argument("set_state: invalid time of the last collision");
    {
        std::vector<char> seen(N, 0);
        for (std::size_t i = 0; i < N; ++i) {
            const std::int32_t o = s.order[i];
            if (o < 0 || o >= n_ || seen[static_cast<std::size_t>(o)])
                throw std::invalid_argument("set_state: order is not a permutation");
            seen[static_cast<std::size_t>(o)] = 1;
        }
    }
    const bool events = !s.ev_time.empty();
    if (events && (s.ev_time.size() != N + 1 || s.ev_partner.size() != N + 1 ||
                   s.ev_count.size() != N + 1 || s.co_time.size() != N ||
                   s.co_partner.size() != N || s.co_count.size() != N))
        throw std::invalid_argument("set_state: event arrays do not match this system");
    const double t = s.scalars[0];
    if (events) {
        for (std::size_t i = 0; i < N; ++i)
            if (s.co_partner[i] < -1 || s.co_partner[i] >= n_ || std::isnan(s.co_time[i]))
                throw std::invalid_argument("set_state: invalid collision candidate");
        for (std::size_t i = 0; i <= N; ++i) {
            const std::int32_t p = s.ev_partner[i];
            bool ok;
            if (i == N)
                ok = p == kReshuffle;
            else if (p >= 0)
                ok = p < n_ && p != static_cast<std::int32_t>(i);
            else if (p == kLowerWall || p == kUpperWall)
                ok = p_.wall[p == kLowerWall ? 0 : 1].present;
            else if (p >= -6)
                ok = (p >= -3 ? -p - 1 : -p - 4) < p_.dim;  // a crossing along an axis in use
            else
                ok = p == kNone;
            if (!ok || std::isnan(s.ev_time[i]) || s.ev_time[i] < t)
                throw std::invalid_argument("set_state: invalid scheduled event");
        }
    }
    // the cells are checked against the grid of the stored x period (the servo may have scaled
    // it); the grid is put back if the state is rejected
    const double box_x = s.scalars[3], old_box_x = p_.box[0];
    if (!(box_x > 0.0)) throw std::invalid_argument("set_state: invalid box");
    try {
        if (box_x != old_box_x) {
            p_.box[0] = box_x;
            setup_grid();
        }
        for (std::size_t k = 0; k < 3 * N; ++k) {
            const int a = static_cast<int>(k % 3);
            if (s.cell[k] < 0 || s.cell[k] >= ncell_[a])
                throw std::invalid_argument("set_state: cell index out of range");
        }
        const double le_cell = s.scalars[5];
        if (!(le_cell >= 0.0 && le_cell < ncell_[0] && le_cell == std::floor(le_cell)))
            throw std::invalid_argument("set_state: invalid Lees-Edwards cell offset");
    } catch (...) {
        if (p_.box[0] != old_box_x) {
            p_.box[0] = old_box_x;
            setup_grid();
        }
        throw;
    }
    for (std::size_t i = 0; i < N; ++i)
        for (int a = 0; a < 3; ++a) {
            P_[i].x[a] = s.pos[3 * i + a];
            P_[i].v[a] = s.vel[3 * i + a];
            P_[i].t = t;
        }
    for (std::size_t i = 0; i < N; ++i) {
        for (int a = 0; a < 3; ++a) spin_[i].w[a] = s.omega[3 * i + a];
        Book& b = book_[i];
        b.last = s.last[i];
        b.count = s.count[i];
        for (int a = 0; a < 3; ++a) b.cell[a] = s.cell[3 * i + a];
    }
    stress_ = s.stress;
    time_ = t;
    dissipated_ = s.scalars[1];
    gravity_work_ = s.scalars[2];
    le_t_ = s.scalars[4];
    le_cell_ = static_cast<std::int32_t>(s.scalars[5]);
    std::size_t k = 6;
    for (int side = 0; side < 2; ++side) {
        Wall& w = p_.wall[side];
        w.y0 = s.scalars[k++];
        w.t0 = s.scalars[k++];
        w.vn = s.scalars[k++];
        w.u[0] = s.scalars[k++];
        w.u[2] = s.scalars[k++];
    }
    for (int side = 0; side < 2; ++side)
        for (int a = 0; a < 3; ++a) wall_impulse_[side][a] = s.scalars[k++];
    wall_work_[0] = s.scalars[k++];
    wall_work_[1] = s.scalars[k++];
    for (int a = 0; a < 9; ++a) virial_[a] = s.scalars[k++];
    p_.stress_lo = s.scalars[k++];
    p_.stress_width = s.scalars[k++];
    p_.stress_bins = static_cast<std::int64_t>(s.scalars[k++]);
    collisions_ = s.counters[0];
    crossings_ = s.counters[1];
    invalid_ = s.counters[2];
    tc_elastic_ = s.counters[3];
    resting_ = s.counters[4];
    wall_collisions_ = s.counters[5];
    log_seen_ = s.counters[6];
    sorted_at_ = s.counters[7];
    {
        // masses and radii follow the stored order (the system may have been re-sorted)
        std::vector<double> m(N), r(N);
        std::vector<std::int8_t> f(N);
        for (std::size_t k = 0; k < N; ++k) {
            m[static_cast<std::size_t>(order_[k])] = spin_[k].m;
            r[static_cast<std::size_t>(order_[k])] = P_[k].r;
            f[static_cast<std::size_t>(order_[k])] = book_[k].fixed;
        }
        order_ = s.order;
        for (std::size_t k = 0; k < N; ++k) {
            spin_[k].m = m[static_cast<std::size_t>(order_[k])];
            P_[k].r = r[static_cast<std::size_t>(order_[k])];
            book_[k].fixed = f[static_cast<std::size_t>(order_[k])];
        }
    }
    log_.clear();
    build_cells();
    if (events) {
        for (std::int32_t k = 0; k <= static_cast<std::int32_t>(n_); ++k) {
            node_at(k) = Node{s.ev_time[k], k};
            book_[k].pos_in_heap = k;
        }
        for (std::size_t i = 0; i <= N; ++i) {
            Book& b = book_[i];
            b.ev_partner = s.ev_partner[i];
            if (i == N) break;
            b.co_t = s.co_time[i];
            b.co_partner = s.co_partner[i];
            b.co_count = s.co_count[i];
        }
    } else {
        predict_all();
        schedule_system();
    }
    heap_build();
}

std::int64_t EventDriven::memory_bytes() const {
    auto b = [](const auto& v) {
        return static_cast<std::int64_t>(v.capacity() * sizeof(v[0]));
    };
    return b(P_) + b(order_) + b(spin_) + b(book_) + b(head_) + b(next_) + b(prev_) +
           b(heap_) + b(stress_) + b(log_) +
           static_cast<std::int64_t>(sizeof(*this));
}

double EventDriven::min_gap() const {
    double best = kInf;
    for (std::int32_t i = 0; i < static_cast<std::int32_t>(n_); ++i) {
        double xi[3], vi[3];
        state_at(i, time_, xi, vi);
        for_neighbours(i, -1, 0, [&](std::int32_t j, const double* sh, const double*) {
            if (j <= i || (book_[i].fixed != 0 && book_[j].fixed != 0)) return;
            double xj[3], vj[3];
            state_at(j, time_, xj, vj);
            double dr[3];
            for (int a = 0; a < 3; ++a) dr[a] = xj[a] + (sh ? sh[a] : 0.0) - xi[a];
            best = std::min(best, std::sqrt(dot3(dr, dr)) - P_[i].r - P_[j].r);
        });
    }
    return best;
}

double EventDriven::min_wall_gap() const {
    double best = kInf;
    for (std::int32_t i = 0; i < static_cast<std::int32_t>(n_); ++i) {
        if (book_[i].fixed != 0) continue;
        double x[3], v[3];
        state_at(i, time_, x, v);
        if (p_.wall[0].present)
            best = std::min(best, x[1] - P_[i].r - p_.wall[0].position(time_));
        if (p_.wall[1].present)
            best = std::min(best, p_.wall[1].position(time_) - x[1] - P_[i].r);
    }
    return best;
}

}  // namespace demstudy::edmd
