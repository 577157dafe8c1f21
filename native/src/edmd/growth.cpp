// Lubachevsky–Stillinger growth (see edmd/growth.hpp). Dimensionless particle units: d = 1,
// m = 1.
#include "edmd/growth.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <queue>
#include <string>
#include <vector>

namespace demstudy::edmd {

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr std::int32_t kLower = -1, kUpper = -2;  // wall partners
// crossing partners: -(3 + 2 axis + (dir > 0))
constexpr std::int32_t kCrossBase = -3;

struct Event {
    double t;
    std::int32_t i, j;
    std::int64_t version_i, count_j;
    bool operator>(const Event& o) const { return t > o.t || (t == o.t && i > o.i); }
};

class Grower {
public:
    Grower(const GrowthParams& p, std::int64_t n, double* pos, double* vel, const double* d,
           const double* m)
        : p_(p), n_(static_cast<std::int32_t>(n)), x_(pos), v_(vel), d_(d), m_(m),
          t_(n, 0.0), version_(n, 0), count_(n, 0), cell_(3 * n, 0), next_(n, -1),
          prev_(n, -1) {
        double dmax = 0.0;
        for (std::int32_t i = 0; i < n_; ++i) dmax = std::max(dmax, d_[i]);
        for (int a = 0; a < 3; ++a) {
            if (a >= p_.dim) {
                nc_[a] = 1;
                cw_[a] = 1.0;
                org_[a] = 0.0;
                continue;
            }
            const bool per = periodic(a);
            const double lo = per ? 0.0 : p_.y_lo;
            const double len = per ? p_.box[a] : p_.y_hi - p_.y_lo;
            if (!(len > 0.0)) throw std::invalid_argument("growth: empty region along an axis");
            nc_[a] = std::max(1, static_cast<int>(std::floor(len / (dmax * p_.s_end))));
            // 1 or 2 cells along a periodic axis: the neighbour loop then visits every
            // image at -L, 0, +L (the wrap gives the shift); the nearest image is the touching
            // one while L >= 2 d_max
            if (per && len < 2.0 * dmax * p_.s_end)
                throw std::invalid_argument(
                    "growth: a periodic box length is below 2 particle diameters (axis " +
                    std::to_string(a) + ")");
            cw_[a] = len / nc_[a];
            org_[a] = lo;
        }
        head_.assign(static_cast<std::size_t>(nc_[0]) * nc_[1] * nc_[2], -1);
        for (std::int32_t i = 0; i < n_; ++i) {
            for (int a = 0; a < p_.dim; ++a) {
                double& xa = x_[3 * i + a];
                if (periodic(a)) xa -= p_.box[a] * std::floor(xa / p_.box[a]);
                int c = static_cast<int>(std::floor((xa - org_[a]) / cw_[a]));
                cell_[3 * i + a] = std::clamp(c, 0, nc_[a] - 1);
            }
            insert(i);
        }
    }

    GrowthResult run() {
        GrowthResult r;
        const double grow_time = (p_.s_end - p_.s_start) / p_.rate;
        s0_ = p_.s_start;
        rate_ = p_.rate;
        tphase_ = 0.0;
        check_start();
        bool ok = true;
        while (ok && now_ < grow_time - 1e-12) {
            ok = run_until(std::min(grow_time, now_ + p_.chunk), r);
            rescale();
        }
        if (ok) {
            s0_ = p_.s_end;
            rate_ = 0.0;
            tphase_ = now_;
            virial_ = 0.0;
            const double t_relax0 = now_;
            const double end = now_ + p_.relax_time;
            while (ok && now_ < end - 1e-12) {
                ok = run_until(std::min(end, now_ + p_.chunk), r);
                rescale();
            }
            // elastic at rate 0: the rescalings only undo round-off drift
            r.relax_virial = now_ > t_relax0 ? virial_ : 0.0;
        }
        r.reached = ok;
        r.scale = scale(now_);
        r.time = now_;
        r.collisions = collisions_;
        r.events = events_;
        for (std::int32_t i = 0; i < n_; ++i)
            for (int a = 0; a < p_.dim; ++a)
                if (periodic(a)) {
                    double& xa = x_[3 * i + a];
                    xa -= p_.box[a] * std::floor(xa / p_.box[a]);
                    if (xa >= p_.box[a]) xa = 0.0;
                }
        return r;
    }

private:
    const GrowthParams& p_;
    std::int32_t n_;
    double* x_;
    double* v_;
    const double* d_;
    const double* m_;
    std::vector<double> t_;
    std::vector<std::int64_t> version_, count_;
    std::vector<int> cell_;
    std::vector<std::int32_t> head_, next_, prev_;
    int nc_[3] = {1, 1, 1};
    double cw_[3] = {1.0, 1.0, 1.0}, org_[3] = {0.0, 0.0, 0.0};
    double now_ = 0.0, s0_ = 0.0, rate_ = 0.0, tphase_ = 0.0, virial_ = 0.0;
    std::int64_t collisions_ = 0, events_ = 0;
    std::priority_queue<Event, std::vector<Event>, std::greater<Event>> heap_;

    bool periodic(int a) const { return a != 1 || p_.periodic_y; }
    double scale(double t) const { return s0_ + rate_ * (t - tphase_); }
    std::size_t cell_index(const int* c) const {
        return (static_cast<std::size_t>(c[2]) * nc_[1] + c[1]) * nc_[0] + c[0];
    }
    void insert(std::int32_t i) {
        const std::size_t c = cell_index(&cell_[3 * i]);
        prev_[i] = -1;
        next_[i] = head_[c];
        if (head_[c] >= 0) prev_[head_[c]] = i;
        head_[c] = i;
    }
    void remove(std::int32_t i) {
        if (prev_[i] >= 0) next_[prev_[i]] = next_[i];
        else head_[cell_index(&cell_[3 * i])] = next_[i];
        if (next_[i] >= 0) prev_[next_[i]] = prev_[i];
    }
    void advance(std::int32_t i, double t) {
        const double dt = t - t_[i];
        for (int a = 0; a < p_.dim; ++a) x_[3 * i + a] += v_[3 * i + a] * dt;
        t_[i] = t;
    }
    void sync() {
        for (std::int32_t i = 0; i < n_; ++i) advance(i, now_);
    }

    // Visit every particle j != i in the cells adjacent to i's with the image shift that
    // brings j next to i.
    template <typename F>
    void for_neighbours(std::int32_t i, F&& visit) const {
        const int* ci = &cell_[3 * i];
        const int lim[3] = {p_.dim > 0 ? 1 : 0, 1, p_.dim == 3 ? 1 : 0};
        for (int oz = -lim[2]; oz <= lim[2]; ++oz)
            for (int oy = -lim[1]; oy <= lim[1]; ++oy)
                for (int ox = -lim[0]; ox <= lim[0]; ++ox) {
                    const int off[3] = {ox, oy, oz};
                    int c[3];
                    double shift[3] = {0.0, 0.0, 0.0};
                    bool skip = false;
                    for (int a = 0; a < 3; ++a) {
                        c[a] = ci[a] + off[a];
                        if (c[a] < 0 || c[a] >= nc_[a]) {
                            if (!periodic(a) || a >= p_.dim) {
                                skip = true;
                                break;
                            }
                            shift[a] = c[a] < 0 ? -p_.box[a] : p_.box[a];
                            c[a] = c[a] < 0 ? nc_[a] - 1 : 0;
                        }
                    }
                    if (skip) continue;
                    for (std::int32_t j = head_[cell_index(c)]; j >= 0; j = next_[j])
                        if (j != i) visit(j, shift);
                }
    }

    // dr = r_j + shift - r_i and dv at time now_ (both extrapolated).
    void separation(std::int32_t i, std::int32_t j, const double* shift, double dr[3],
                    double dv[3]) const {
        for (int a = 0; a < 3; ++a) {
            dr[a] = 0.0;
            dv[a] = 0.0;
        }
        for (int a = 0; a < p_.dim; ++a) {
            const double xi = x_[3 * i + a] + v_[3 * i + a] * (now_ - t_[i]);
            const double xj = x_[3 * j + a] + v_[3 * j + a] * (now_ - t_[j]);
            dr[a] = xj + shift[a] - xi;
            dv[a] = v_[3 * j + a] - v_[3 * i + a];
        }
    }

    double pair_time(std::int32_t i, std::int32_t j, const double* shift) const {
        double dr[3], dv[3];
        separation(i, j, shift, dr, dv);
        const double A = 0.5 * (d_[i] + d_[j]);
        const double s = scale(now_);
        const double rr = dr[0] * dr[0] + dr[1] * dr[1] + dr[2] * dr[2];
        const double rv = dr[0] * dv[0] + dr[1] * dv[1] + dr[2] * dv[2];
        const double vv = dv[0] * dv[0] + dv[1] * dv[1] + dv[2] * dv[2];
        const double c = rr - A * A * s * s;
        const double b = rv - A * A * s * rate_;  // < 0: the gap closes
        const double qa = vv - A * A * rate_ * rate_;
        if (c <= 0.0) return b < 0.0 ? 0.0 : kInf;
        if (b >= 0.0 && qa >= 0.0) return kInf;
        const double disc = b * b - qa * c;
        if (disc < 0.0) return kInf;
        const double den = -b + std::sqrt(disc);
        return den > 0.0 ? c / den : kInf;
    }

    double wall_time(std::int32_t i, int side) const {
        const double y = x_[3 * i + 1] + v_[3 * i + 1] * (now_ - t_[i]);
        const double r = 0.5 * d_[i] * scale(now_), rdot = 0.5 * d_[i] * rate_;
        const double vy = v_[3 * i + 1];
        const double gap = side == 0 ? y - r - p_.y_lo : p_.y_hi - y - r;
        const double closing = side == 0 ? rdot - vy : vy + rdot;
        if (closing <= 0.0) return kInf;
        return gap <= 0.0 ? 0.0 : gap / closing;
    }

    double crossing_time(std::int32_t i, std::int32_t& code) const {
        double best = kInf;
        for (int a = 0; a < p_.dim; ++a) {
            const double va = v_[3 * i + a];
            if (va == 0.0) continue;
            const int c = cell_[3 * i + a];
            const bool up = va > 0.0;
            if (!periodic(a) && ((up && c == nc_[a] - 1) || (!up && c == 0))) continue;
            const double edge = org_[a] + (up ? c + 1 : c) * cw_[a];
            const double xa = x_[3 * i + a] + va * (now_ - t_[i]);
            const double tt = std::max(0.0, (edge - xa) / va);
            if (tt < best) {
                best = tt;
                code = kCrossBase - (2 * a + (up ? 1 : 0));
            }
        }
        return best;
    }

    void predict(std::int32_t i) {
        ++version_[i];
        std::int32_t code = 0;
        double best = crossing_time(i, code);
        std::int32_t partner = code;
        if (!p_.periodic_y) {
            for (int side = 0; side < 2; ++side) {
                const double tw = wall_time(i, side);
                if (tw < best) {
                    best = tw;
                    partner = side == 0 ? kLower : kUpper;
                }
            }
        }
        for_neighbours(i, [&](std::int32_t j, const double* shift) {
            const double tp = pair_time(i, j, shift);
            if (tp < best) {
                best = tp;
                partner = j;
            }
        });
        if (best < kInf)
            heap_.push({now_ + best, i, partner, version_[i], partner >= 0 ? count_[partner] : 0});
    }

    void predict_all() {
        heap_ = decltype(heap_)();
        for (std::int32_t i = 0; i < n_; ++i) predict(i);
    }

    // Reflect the normal relative velocity in the frame of the growing surfaces.
    void collide_pair(std::int32_t i, std::int32_t j) {
        advance(i, now_);
        advance(j, now_);
        // at contact the nearest image is the touching one (periodic lengths >= 2 d_max)
        double best_shift[3] = {0.0, 0.0, 0.0};
        for (int a = 0; a < p_.dim; ++a) {
            if (!periodic(a)) continue;
            const double delta = x_[3 * j + a] - x_[3 * i + a];
            best_shift[a] = -p_.box[a] * std::round(delta / p_.box[a]);
        }
        double dr[3], dv[3];
        separation(i, j, best_shift, dr, dv);
        const double dist = std::sqrt(dr[0] * dr[0] + dr[1] * dr[1] + dr[2] * dr[2]);
        const double A = 0.5 * (d_[i] + d_[j]);
        const double u = (dr[0] * dv[0] + dr[1] * dv[1] + dr[2] * dv[2]) / dist;
        const double du = 2.0 * (A * rate_ - u);
        if (du > 0.0) {
            const double mu = m_[i] * m_[j] / (m_[i] + m_[j]);
            for (int a = 0; a < p_.dim; ++a) {
                const double na = dr[a] / dist;
                v_[3 * j + a] += mu * du / m_[j] * na;
                v_[3 * i + a] -= mu * du / m_[i] * na;
            }
            virial_ += mu * du * dist;
        }
        ++count_[i];
        ++count_[j];
        ++collisions_;
        predict(i);
        predict(j);
    }

    void collide_wall(std::int32_t i, int side) {
        advance(i, now_);
        const double rdot = 0.5 * d_[i] * rate_;
        double& vy = v_[3 * i + 1];
        if (side == 0 && vy < rdot) vy = 2.0 * rdot - vy;
        if (side == 1 && vy > -rdot) vy = -vy - 2.0 * rdot;
        ++count_[i];
        ++collisions_;
        predict(i);
    }

    void cross(std::int32_t i, std::int32_t code) {
        advance(i, now_);
        const int k = kCrossBase - code;
        const int a = k / 2;
        const bool up = (k % 2) == 1;
        remove(i);
        int& c = cell_[3 * i + a];
        c += up ? 1 : -1;
        if (c >= nc_[a]) {
            c = 0;
            x_[3 * i + a] -= p_.box[a];
        } else if (c < 0) {
            c = nc_[a] - 1;
            x_[3 * i + a] += p_.box[a];
        }
        insert(i);
        predict(i);
    }

    // Process events up to time `until`; false when max_events is exceeded.
    bool run_until(double until, GrowthResult&) {
        predict_all();
        while (!heap_.empty()) {
            const Event e = heap_.top();
            if (e.t > until) break;
            heap_.pop();
            if (e.version_i != version_[e.i]) continue;  // superseded prediction
            now_ = std::max(now_, e.t);
            if (e.j >= 0 && e.count_j != count_[e.j]) {
                predict(e.i);  // the partner changed course: predict again
                continue;
            }
            ++events_;
            if (p_.max_events > 0 && events_ > p_.max_events) return false;
            if (e.j >= 0) collide_pair(e.i, e.j);
            else if (e.j == kLower) collide_wall(e.i, 0);
            else if (e.j == kUpper) collide_wall(e.i, 1);
            else cross(e.i, e.j);
        }
        now_ = until;
        sync();
        return true;
    }

    void rescale() {
        double ke = 0.0;
        for (std::int32_t i = 0; i < n_; ++i)
            for (int a = 0; a < p_.dim; ++a) ke += m_[i] * v_[3 * i + a] * v_[3 * i + a];
        const double temp = ke / (p_.dim * static_cast<double>(n_));
        if (!(temp > 0.0)) return;
        const double f = std::sqrt(p_.temperature / temp);
        for (std::int32_t i = 0; i < 3 * n_; ++i) v_[i] *= f;
    }

    void check_start() {
        for (std::int32_t i = 0; i < n_; ++i) {
            for_neighbours(i, [&](std::int32_t j, const double* shift) {
                if (j < i) return;
                double dr[3], dv[3];
                separation(i, j, shift, dr, dv);
                const double A = 0.5 * (d_[i] + d_[j]) * scale(now_);
                if (dr[0] * dr[0] + dr[1] * dr[1] + dr[2] * dr[2] < A * A * (1 - 1e-9))
                    throw std::invalid_argument("growth: the start has overlapping particles");
            });
        }
    }
};

}  // namespace

GrowthResult grow_packing(const GrowthParams& p, std::int64_t n, double* pos, double* vel,
                          const double* diameter, const double* mass) {
    if (p.dim != 2 && p.dim != 3) throw std::invalid_argument("growth: dim must be 2 or 3");
    if (!(p.rate > 0.0) || !(p.s_start > 0.0) || !(p.s_end >= p.s_start) || !(p.chunk > 0.0))
        throw std::invalid_argument("growth: needs rate > 0, 0 < s_start <= s_end, chunk > 0");
    if (n <= 0) return GrowthResult{true, p.s_end, 0, 0, 0.0, 0.0};
    Grower g(p, n, pos, vel, diameter, mass);
    return g.run();
}

}  // namespace demstudy::edmd
