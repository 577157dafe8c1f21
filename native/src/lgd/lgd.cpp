// The step of Gutt's (1989) lattice grain dynamics: the C listing's main loop, uppo, colb,
// colc, colf, serial (periodic columns instead of the hypercube's halo exchange). Integer
// arithmetic as the listing's (C++ '/' truncates toward zero like C); the time step in IEEE
// doubles, compiled without FMA contraction so it equals the numpy reference bit for bit.
// Units: the listing's integers; demstudy's dimensionless units (d = 1, m = 1, g = 1) above.
#include "lgd/lgd.hpp"

#include <cmath>

namespace demstudy::lgd {

namespace {

constexpr std::int8_t kWall = -1, kEmpty = 0, kMovable = 1, kMoved = 2;

// move directions d, b, a, c, e, f: (dc, dr) and the sign pattern of the offset correction
enum Dir { D = 0, B, A, C, E, F };
constexpr int kDc[6] = {1, 0, -1, -1, 0, 1};
constexpr int kDr[6] = {0, 1, 1, 0, -1, -1};

// C's truncating division by a positive divisor fixed for the run, without the slow 64-bit
// idiv: a power of two by shifts; otherwise in doubles, exact for |a| < 2^53 (a correctly
// rounded a/d never reaches the next integer: that is >= 1/d away, the rounding error
// <= |a/d|·2^-53 < 1/d), with the integer division kept for larger |a|.
struct Divider {
    std::int64_t d = 1;
    double dd = 1.0;
    int shift = -1;  // log2(d) when d is a power of two
    explicit Divider(std::int64_t divisor = 1) : d(divisor), dd(static_cast<double>(divisor)) {
        if (d > 0 && (d & (d - 1)) == 0) {
            shift = 0;
            while ((std::int64_t{1} << shift) != d) ++shift;
        }
    }
    std::int64_t operator()(std::int64_t a) const {
        if (shift >= 0) return (a + ((a >> 63) & (d - 1))) >> shift;
        constexpr std::int64_t kExact = std::int64_t{1} << 53;
        if (a > -kExact && a < kExact)
            return static_cast<std::int64_t>(static_cast<double>(a) / dd);
        return a / d;
    }
};

inline std::int64_t round_half_away(double x) {
    return static_cast<std::int64_t>(x + (x < 0 ? -0.5 : 0.5));
}

struct Lattice {
    std::int8_t* mlp;
    std::int64_t *ipx, *ipy, *ivx, *ivy;
    std::int32_t* nlp;
    std::int64_t nxt, nyt;
};

// uppo on every mlp == 1 site of one move template (array rows r0::3, columns c0::3)
void move_template(const Params& p, Lattice& L, std::int64_t r0, std::int64_t c0) {
    const std::int64_t nxt = L.nxt;
    const std::int64_t icx[6] = {-p.id2, -p.idx, p.idx, p.id2, p.idx, -p.idx};
    const std::int64_t icy[6] = {0, -p.idy, -p.idy, 0, p.idy, p.idy};
    for (std::int64_t r = r0; r < L.nyt; r += 3) {
        const std::int64_t row = r * nxt;
        const bool odd_row = (r % 2) == 0;  // Gutt's row R = r + 1 is odd
        for (std::int64_t c = c0; c < nxt; c += 3) {
            const std::int64_t m0 = row + c;
            if (L.mlp[m0] != kMovable) continue;
            const std::int64_t ix = L.ipx[m0], iy = L.ipy[m0];
            if (ix < p.idl && ix > -p.idl && iy < p.idl && iy > -p.idl &&
                ix * ix + iy * iy < p.id) {
                L.mlp[m0] = kMoved;  // inside the circle: done for this step
                continue;
            }
            int dir;
            if (ix > 0) {
                const std::int64_t islope = 256 * iy / ix;
                dir = islope <= -148 ? F : (islope < 148 ? D : B);
            } else if (ix < 0) {
                const std::int64_t islope = 256 * iy / ix;
                dir = islope >= 148 ? E : (islope > -148 ? C : A);
            } else if (iy < 0) {
                dir = odd_row ? F : E;
            } else {
                dir = odd_row ? B : A;
            }
            std::int64_t cc = c + kDc[dir];
            if (cc < 0) cc += nxt;
            else if (cc >= nxt) cc -= nxt;
            const std::int64_t m1 = (r + kDr[dir]) * nxt + cc;
            if (L.mlp[m1] != kEmpty) continue;  // blocked: retry in a later template
            L.ipx[m1] = ix + icx[dir];
            L.ipy[m1] = iy + icy[dir];
            L.ivx[m1] = L.ivx[m0];
            L.ivy[m1] = L.ivy[m0];
            L.mlp[m1] = static_cast<std::int8_t>(L.mlp[m0] + 1);
            L.nlp[m1] = L.nlp[m0];
            L.ipx[m0] = L.ipy[m0] = L.ivx[m0] = L.ivy[m0] = 0;
            L.mlp[m0] = kEmpty;
            L.nlp[m0] = 0;
        }
    }
}

// the run's fixed divisors
struct Divs {
    Divider kq, kqp, kqw, id2, ke, ke1;
    explicit Divs(const Params& p)
        : kq(p.kq), kqp(p.kqp), kqw(p.kqw), id2(p.id2), ke(p.ke), ke1(p.ke1) {}
};

// ikc = ke·(1+e)·kc with the piecewise restitution
inline std::int64_t impulse(const Params& p, std::int64_t kc1, bool wall) {
    if (kc1 <= p.icb) return (wall ? p.iew1 : p.iep1) * kc1;
    std::int64_t ikc = (wall ? p.icw : p.icp) + (wall ? p.iew2 : p.iep2) * kc1;
    if (ikc < 0) ikc = 0;  // the rebound cannot be negative
    return ikc + p.ke * kc1;
}

// remove the offset component along k = (½, sy·√3/2), keep the perpendicular one
inline void project(const Params& p, const Divs& dv, std::int64_t& px, std::int64_t& py,
                    std::int64_t sy) {
    const std::int64_t ip = dv.id2(p.idy * px - sy * p.idx * py);
    px = dv.id2(ip * p.idy);
    py = dv.id2(-sy * ip * p.idx);
}

// colb (sy = +1, partner (r+1, c)) or colf (sy = -1, partner (r-1, c+1)) on one template
void collide_bf(const Params& p, const Divs& dv, Lattice& L, std::int64_t r0, std::int64_t c0,
                int sy) {
    const std::int64_t nxt = L.nxt;
    const std::int64_t r_lo = sy > 0 ? 0 : 1, r_hi = sy > 0 ? L.nyt - 1 : L.nyt;
    std::int64_t r = r0;
    while (r < r_lo) r += 2;
    for (; r < r_hi; r += 2) {
        const std::int64_t row = r * nxt;
        const std::int64_t prow = (sy > 0 ? r + 1 : r - 1) * nxt;
        for (std::int64_t c = c0; c < nxt; c += 2) {
            const std::int64_t m0 = row + c;
            const std::int8_t a0 = L.mlp[m0];
            if (a0 == kEmpty) continue;
            std::int64_t c1 = c + (sy > 0 ? 0 : 1);
            if (c1 >= nxt) c1 -= nxt;
            const std::int64_t m1 = prow + c1;
            const std::int8_t a1 = L.mlp[m1];
            if (a1 == kEmpty || (a0 < 0 && a1 < 0)) continue;
            const std::int64_t num =
                p.kx * (L.ivx[m0] - L.ivx[m1]) + sy * p.ky * (L.ivy[m0] - L.ivy[m1]) + p.kx;
            if (num < p.kq) continue;  // kc1 = num/kq (truncated) <= 0: not approaching
            const std::int64_t kc1 = dv.kq(num);
            const bool wall = a0 < 0 || a1 < 0;
            const std::int64_t ikc = impulse(p, kc1, wall);
            const std::int64_t add = wall ? p.kxw : p.kxp;
            const Divider& den = wall ? dv.kqw : dv.kqp;
            const std::int64_t dvx = den(p.kx * ikc + add);  // Δv of m1; m0 gets −Δv
            const std::int64_t dvy = sy * den(p.ky * ikc + add);
            if (a0 < 0) {  // wall at m0: it accumulates −Δv(grain)
                L.ipx[m0] -= dvx;
                L.ipy[m0] -= dvy;
            } else {
                L.ivx[m0] -= dvx;
                L.ivy[m0] -= dvy;
                project(p, dv, L.ipx[m0], L.ipy[m0], sy);
            }
            if (a1 < 0) {
                L.ipx[m1] += dvx;
                L.ipy[m1] += dvy;
            } else {
                L.ivx[m1] += dvx;
                L.ivy[m1] += dvy;
                project(p, dv, L.ipx[m1], L.ipy[m1], sy);
            }
        }
    }
}

// colc: partner (r, c-1), k = (-1, 0)
void collide_c(const Params& p, const Divs& dv, Lattice& L, std::int64_t r0, std::int64_t c0) {
    const std::int64_t nxt = L.nxt;
    for (std::int64_t r = r0; r < L.nyt; r += 2) {
        const std::int64_t row = r * nxt;
        for (std::int64_t c = c0; c < nxt; c += 2) {
            const std::int64_t m0 = row + c;
            const std::int8_t a0 = L.mlp[m0];
            if (a0 == kEmpty) continue;
            const std::int64_t m1 = row + (c == 0 ? nxt - 1 : c - 1);
            const std::int8_t a1 = L.mlp[m1];
            if (a1 == kEmpty || (a0 < 0 && a1 < 0)) continue;
            const std::int64_t kc1 = L.ivx[m1] - L.ivx[m0];
            if (kc1 <= 0) continue;
            const bool wall = a0 < 0 || a1 < 0;
            const std::int64_t ikc = impulse(p, kc1, wall);
            const std::int64_t ikcx = wall ? dv.ke(ikc + p.ke2) : dv.ke1(ikc + p.ke);
            if (a0 < 0) {
                L.ipx[m0] += ikcx;
            } else {
                L.ivx[m0] += ikcx;
                L.ipx[m0] = 0;
            }
            if (a1 < 0) {
                L.ipx[m1] -= ikcx;
            } else {
                L.ivx[m1] -= ikcx;
                L.ipx[m1] = 0;
            }
        }
    }
}

// the 12 sub-sweeps; template t (1..4) has (G parity, R parity) = (0,0), (1,0), (0,1), (1,1)
// with G = c + 1, R = r + 1, i.e. first array column 1 - Gpar, first array row 1 - Rpar
void collide_sweep(const Params& p, const Divs& dv, Lattice& L, std::int64_t nn) {
    static const int kTemplate[12] = {3, 3, 3, 2, 2, 2, 4, 4, 4, 1, 1, 1};
    static const char kBond[12] = {'b', 'c', 'f', 'f', 'c', 'b', 'b', 'c', 'f', 'f', 'c', 'b'};
    static const int kC0[5] = {0, 1, 0, 1, 0}, kR0[5] = {0, 1, 1, 0, 0};
    const bool odd = (nn % 2) != 0;
    for (int k = 0; k < 12; ++k) {
        const int j = odd ? k : 11 - k;
        const int t = kTemplate[j];
        const char bond = kBond[j];
        if (bond == 'c') collide_c(p, dv, L, kR0[t], kC0[t]);
        else collide_bf(p, dv, L, kR0[t], kC0[t], bond == 'b' ? 1 : -1);
    }
}

}  // namespace

std::int64_t time_step(const Params& p, std::int64_t pv2i, std::int64_t pvx, std::int64_t pvy) {
    const double pv2 = static_cast<double>(pv2i);
    const double pv1 = std::sqrt(pv2);
    if (p.gm == 0.0) return pv1 > 0.0 ? static_cast<std::int64_t>(p.dl3 / pv1 + 0.5) : 1;
    const double gv = static_cast<double>(p.igx * pvx + p.igy * pvy);
    std::int64_t it =
        static_cast<std::int64_t>(2.0 * p.dy3 / (std::sqrt(pv2 + 2.0 * p.dy1 * p.gm) + pv1) +
                                  0.5) - 1;
    double rt = static_cast<double>(it) / 256.0;
    double dp = rt * std::sqrt((0.25 * p.gm2 * rt + gv) * rt + pv2) - p.dy1;
    double dl;
    do {
        dl = dp;
        ++it;
        rt = static_cast<double>(it) / 256.0;
        dp = rt * std::sqrt((0.25 * p.gm2 * rt + gv) * rt + pv2) - p.dy1;
    } while (dp < 0.0 && it < p.itm);
    if (dp > -dl) --it;  // the overshoot exceeds the undershoot: the smaller it
    return it;
}

void run_steps(const Params& p, State& s, std::int64_t n_steps, std::int64_t* log) {
    Lattice L{s.mlp, s.ipx, s.ipy, s.ivx, s.ivy, s.nlp, s.nxt, s.nyt};
    const Divs divs(p);
    const std::int64_t nxt = s.nxt, nyt = s.nyt, n = nxt * nyt;
    static const int kMoveA[9] = {0, 2, 1, 2, 1, 0, 1, 0, 2};
    static const int kMoveB[9] = {0, 1, 2, 0, 1, 2, 0, 1, 2};
    for (std::int64_t step = 0; step < n_steps; ++step) {
        const std::int64_t it = time_step(p, s.pv2, s.pvx, s.pvy);
        const double gx = static_cast<double>(p.igx * it) / 256.0;
        const double gy = static_cast<double>(p.igy * it) / 256.0;
        const std::int64_t igtx = round_half_away(gx), igty = round_half_away(gy);
        const std::int64_t idpx = round_half_away(gx / 2.0), idpy = round_half_away(gy / 2.0);
        for (std::int64_t m = 0; m < n; ++m) {
            if (L.mlp[m] != kMovable) continue;
            L.ipx[m] += (L.ivx[m] + idpx) * it / 4096;
            L.ipy[m] += (L.ivy[m] + idpy) * it / 4096;
            L.ivx[m] += igtx;
            L.ivy[m] += igty;
        }
        for (std::int64_t pass = 0; pass < p.ntu; ++pass)
            for (int k = 0; k < 9; ++k)  // template (G ≡ a, R ≡ b mod 3), G = c + 1, R = r + 1
                move_template(p, L, (kMoveB[k] + 2) % 3, (kMoveA[k] + 2) % 3);
        collide_sweep(p, divs, L, s.nn);
        std::int64_t wsum[6] = {0, 0, 0, 0, 0, 0};  // is1 ip1 is2 ip2 is3 ip3
        for (int w = 0; w < 2; ++w) {
            const std::int64_t row = (w == 0 ? 0 : nyt - 1) * nxt;
            for (std::int64_t c = 0; c < nxt; ++c) {
                wsum[2 * w] += L.ipx[row + c];
                wsum[2 * w + 1] += L.ipy[row + c];
                L.ipx[row + c] = L.ipy[row + c] = 0;
            }
        }
        std::int64_t svx = 0, svy = 0, sv2 = 0, nq = 0, pv2 = 0, pvx = 0, pvy = 0;
        const std::int64_t half = nxt / 2;
        for (std::int64_t r = 0; r < nyt; ++r) {
            const std::int64_t row = r * nxt;
            for (std::int64_t c = 0; c < nxt; ++c) {
                const std::int64_t m = row + c;
                const std::int8_t a = L.mlp[m];
                if (a == kEmpty) continue;
                if (a < 0) {
                    wsum[4] += L.ipx[m];
                    wsum[5] += L.ipy[m];
                    L.ipx[m] = L.ipy[m] = 0;
                    continue;
                }
                if (p.nw > 0 && (c + r / 2) % nxt + 1 > half) ++nq;
                if (a == kMoved) L.mlp[m] = kMovable;
                const std::int64_t vx = L.ivx[m], vy = L.ivy[m], v2 = vx * vx + vy * vy;
                svx += vx;
                svy += vy;
                sv2 += v2;
                if (v2 > pv2) {
                    pv2 = v2;
                    pvx = vx;
                    pvy = vy;
                }
            }
        }
        s.pv2 = pv2;
        s.pvx = pvx;
        s.pvy = pvy;
        s.itt += it;
        std::int64_t* out = log + step * kLogFields;
        const std::int64_t row_out[kLogFields] = {s.nn, it, s.itt, svx, svy, sv2, pv2,
                                                  wsum[0], wsum[1], wsum[2], wsum[3],
                                                  wsum[4], wsum[5], nq};
        for (int k = 0; k < kLogFields; ++k) out[k] = row_out[k];
        s.nn += 1;
    }
}

}  // namespace demstudy::lgd
