// Event-driven hard discs / spheres: see native/include/edmd/edmd.hpp.
// Dimensionless particle units: d = 1, m = 1.
#include "edmd/edmd.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

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
}  // namespace

void collide_pair(const double n[3], double ri, double rj, double mi, double mj,
                  double inertia_k, double e, double beta, double vi[3], double vj[3],
                  double wi[3], double wj[3], double J[3]) {
    // relative velocity of the contact points, g = vi - vj + (ri wi + rj wj) x n
    double s[3], sxn[3], g[3];
    for (int a = 0; a < 3; ++a) s[a] = ri * wi[a] + rj * wj[a];
    cross3(s, n, sxn);
    for (int a = 0; a < 3; ++a) g[a] = vi[a] - vj[a] + sxn[a];
    const double gn = dot3(g, n);
    const double meff = mi * mj / (mi + mj);
    const bool rotating = inertia_k > 0.0 && beta > -1.0;
    const double ct = rotating ? meff * (1.0 + beta) * inertia_k / (1.0 + inertia_k) : 0.0;
    for (int a = 0; a < 3; ++a) {
        const double gt = g[a] - gn * n[a];
        J[a] = -meff * (1.0 + e) * gn * n[a] - ct * gt;
    }
    for (int a = 0; a < 3; ++a) {
        vi[a] += J[a] / mi;
        vj[a] -= J[a] / mj;
    }
    if (rotating) {
        double nxj[3];
        cross3(n, J, nxj);
        const double fi = 1.0 / (inertia_k * mi * ri), fj = 1.0 / (inertia_k * mj * rj);
        for (int a = 0; a < 3; ++a) {
            wi[a] += fi * nxj[a];
            wj[a] += fj * nxj[a];
        }
    }
}

EventDriven::EventDriven(const Params& p, std::int64_t n, const double* pos, const double* vel,
                         const double* omega, const double* diameter, const double* mass)
    : p_(p), n_(n) {
    if (p.dim != 2 && p.dim != 3) throw std::invalid_argument("dim must be 2 or 3");
    if (!(p.restitution > 0.0 && p.restitution <= 1.0))
        throw std::invalid_argument("restitution must be in (0, 1]");
    if (!(p.beta >= -1.0 && p.beta <= 1.0)) throw std::invalid_argument("beta must be in [-1, 1]");
    if (!(p.inertia_k >= 0.0)) throw std::invalid_argument("inertia_k must be >= 0");
    if (!(p.tc >= 0.0)) throw std::invalid_argument("tc must be >= 0");
    if (n < 1 || n > (std::int64_t{1} << 30)) throw std::invalid_argument("need 1 <= N < 2^30");
    if (p.dim == 2) p_.box[2] = 1.0;
    const std::size_t N = static_cast<std::size_t>(n);
    P_.assign(N, Particle{});
    w_.assign(3 * N, 0.0);
    last_.assign(N, -kInf);
    m_.resize(N);
    count_.assign(N, 0);
    cell_.assign(3 * N, 0);
    double dmax = 0.0;
    const int nrot = p.dim == 2 ? 1 : 3;
    for (std::size_t i = 0; i < N; ++i) {
        for (int a = 0; a < p.dim; ++a) {
            const double L = p_.box[a];
            double x = pos[i * p.dim + a];
            if (!std::isfinite(x) || !std::isfinite(vel[i * p.dim + a]))
                throw std::invalid_argument("non-finite position or velocity");
            x = x - L * std::floor(x / L);
            if (x >= L) x -= L;
            P_[i].x[a] = x;
            P_[i].v[a] = vel[i * p.dim + a];
        }
        if (nrot == 1)
            w_[3 * i + 2] = omega[i];
        else
            for (int a = 0; a < 3; ++a) w_[3 * i + a] = omega[3 * i + a];
        if (!(diameter[i] > 0.0) || !(mass[i] > 0.0))
            throw std::invalid_argument("diameters and masses must be positive");
        P_[i].r = 0.5 * diameter[i];
        m_[i] = mass[i];
        dmax = std::max(dmax, diameter[i]);
    }
    // cells: width >= the largest diameter, at least 3 per axis, at most ~8 per particle
    double width = dmax;
    for (int iter = 0; iter < 200; ++iter) {
        std::int64_t total = 1;
        for (int a = 0; a < p.dim; ++a) {
            ncell_[a] = static_cast<int>(std::floor(p_.box[a] / width));
            total *= ncell_[a];
        }
        if (total <= std::max<std::int64_t>(8 * n, 64)) break;
        width *= 1.1;
    }
    for (int a = 0; a < p.dim; ++a) {
        if (ncell_[a] < 3)
            throw std::invalid_argument(
                "every box length must be at least 3 largest diameters (axis " +
                std::to_string(a) + ": " + std::to_string(p_.box[a]) + ")");
        cw_[a] = p_.box[a] / ncell_[a];
    }
    if (p.dim == 2) {
        ncell_[2] = 1;
        cw_[2] = p_.box[2];
    }
    for (std::size_t i = 0; i < N; ++i)
        for (int a = 0; a < p.dim; ++a) {
            int c = static_cast<int>(std::floor(P_[i].x[a] / cw_[a]));
            cell_[3 * i + a] = std::clamp(c, 0, ncell_[a] - 1);
        }
    // internal order: by cell (neighbours close in memory); order_[internal] = input index
    order_.resize(N);
    for (std::size_t i = 0; i < N; ++i) order_[i] = static_cast<std::int32_t>(i);
    std::stable_sort(order_.begin(), order_.end(), [&](std::int32_t a, std::int32_t b) {
        return cell_index(&cell_[3 * a]) < cell_index(&cell_[3 * b]);
    });
    {
        std::vector<Particle> P(N);
        std::vector<double> w(3 * N), m(N);
        std::vector<std::int32_t> cell(3 * N);
        for (std::size_t k = 0; k < N; ++k) {
            const std::size_t i = static_cast<std::size_t>(order_[k]);
            P[k] = P_[i];
            m[k] = m_[i];
            for (int a = 0; a < 3; ++a) {
                w[3 * k + a] = w_[3 * i + a];
                cell[3 * k + a] = cell_[3 * i + a];
            }
        }
        P_.swap(P);
        w_.swap(w);
        m_.swap(m);
        cell_.swap(cell);
    }
    build_cells();
    co_t_.assign(N, kInf);
    co_partner_.assign(N, -1);
    co_count_.assign(N, 0);
    ev_t_.assign(N, kInf);
    ev_partner_.assign(N, kNone);
    ev_count_.assign(N, 0);
    heap_.resize(N);
    pos_in_heap_.resize(N);
    predict_all();
    heap_build();
}

void EventDriven::build_cells() {
    const std::int64_t total = static_cast<std::int64_t>(ncell_[0]) * ncell_[1] * ncell_[2];
    head_.assign(static_cast<std::size_t>(total), -1);
    next_.assign(static_cast<std::size_t>(n_), -1);
    prev_.assign(static_cast<std::size_t>(n_), -1);
    for (std::int32_t i = static_cast<std::int32_t>(n_) - 1; i >= 0; --i) insert_cell(i);
}

void EventDriven::insert_cell(std::int32_t i) {
    const std::int64_t c = cell_index(&cell_[3 * i]);
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
        head_[cell_index(&cell_[3 * i])] = next_[i];
    if (next_[i] >= 0) prev_[next_[i]] = prev_[i];
}

void EventDriven::advance(std::int32_t i, double t) {
    const double dt = t - P_[i].t;
    if (dt != 0.0) {
        for (int a = 0; a < 3; ++a) P_[i].x[a] += P_[i].v[a] * dt;
        P_[i].t = t;
    }
}

// Separation j - i at time tt, with j's periodic image chosen from the cell offset
// (unambiguous with >= 3 cells per axis).
void EventDriven::image(std::int32_t i, std::int32_t j, double tt, double dr[3]) const {
    for (int a = 0; a < 3; ++a) {
        const int dc = cell_[3 * j + a] - cell_[3 * i + a];
        double shift = 0.0;
        if (dc > 1) shift = -p_.box[a];
        else if (dc < -1) shift = p_.box[a];
        dr[a] = (P_[j].x[a] + P_[j].v[a] * (tt - P_[j].t)) + shift -
                (P_[i].x[a] + P_[i].v[a] * (tt - P_[i].t));
    }
    if (p_.dim == 2) dr[2] = 0.0;
}

// Scan the neighbouring cells of i (only the layer at offset `dir` along `only_axis` when
// only_axis >= 0) and lower i's collision candidate (co_*) where a partner hits earlier.
void EventDriven::scan(std::int32_t i, int only_axis, int dir) {
    const double* xi = P_[i].x;
    const double* vi = P_[i].v;
    const std::int32_t* ci = &cell_[3 * i];
    const int zr = p_.dim == 3 ? 1 : 0;
    double best = co_t_[i] - time_;  // relative to now (inf when there is no candidate)
    std::int32_t partner = co_partner_[i];
    std::int64_t partner_count = co_count_[i];
    for (int dz = -zr; dz <= zr; ++dz)
        for (int dy = -1; dy <= 1; ++dy)
            for (int dx = -1; dx <= 1; ++dx) {
                const int d[3] = {dx, dy, dz};
                if (only_axis >= 0 && d[only_axis] != dir) continue;
                int c[3] = {ci[0] + dx, ci[1] + dy, ci[2] + dz};
                double shift[3] = {0.0, 0.0, 0.0};
                for (int a = 0; a < 3; ++a) {
                    if (d[a] == 0) continue;
                    if (c[a] < 0) {
                        c[a] += ncell_[a];
                        shift[a] = -p_.box[a];
                    } else if (c[a] >= ncell_[a]) {
                        c[a] -= ncell_[a];
                        shift[a] = p_.box[a];
                    }
                }
                for (std::int32_t j = head_[cell_index(c)]; j >= 0; j = next_[j]) {
                    if (j == i) continue;
                    const double* xj = P_[j].x;
                    const double* vj = P_[j].v;
                    const double dtj = time_ - P_[j].t;
                    double dr[3], dv[3];
                    for (int a = 0; a < 3; ++a) {
                        dr[a] = xj[a] + vj[a] * dtj + shift[a] - xi[a];
                        dv[a] = vj[a] - vi[a];
                    }
                    const double b = dot3(dr, dv);
                    if (b >= 0.0) continue;
                    const double sigma = P_[i].r + P_[j].r;
                    const double cc = dot3(dr, dr) - sigma * sigma;
                    double t;
                    if (cc <= 0.0) {
                        t = 0.0;  // touching or overlapping and approaching: collide now
                    } else {
                        const double aa = dot3(dv, dv);
                        const double disc = b * b - aa * cc;
                        if (disc <= 0.0) continue;
                        t = cc / (-b + std::sqrt(disc));
                    }
                    if (t < best || (t == best && partner >= 0 && j < partner)) {
                        best = t;
                        partner = j;
                        partner_count = count_[j];
                    }
                }
            }
    if (partner >= 0) {
        co_t_[i] = time_ + best;
        co_partner_[i] = partner;
        co_count_[i] = partner_count;
    }
}

// i's event: the earlier of its next cell crossing and its collision candidate.
void EventDriven::schedule(std::int32_t i) {
    const double* xi = P_[i].x;
    const double* vi = P_[i].v;
    const std::int32_t* ci = &cell_[3 * i];
    double best = kInf;
    std::int32_t kind = kNone;
    for (int a = 0; a < p_.dim; ++a) {
        double t;
        if (vi[a] > 0.0) {
            const double hi = ci[a] + 1 == ncell_[a] ? p_.box[a] : (ci[a] + 1) * cw_[a];
            t = (hi - xi[a]) / vi[a];
        } else if (vi[a] < 0.0) {
            t = (ci[a] * cw_[a] - xi[a]) / vi[a];
        } else {
            continue;
        }
        if (t < 0.0) t = 0.0;
        if (t < best) {
            best = t;
            kind = -(a + 1);
        }
    }
    const double cross = time_ + best;
    if (co_partner_[i] >= 0 && co_t_[i] <= cross) {
        ev_t_[i] = co_t_[i];
        ev_partner_[i] = co_partner_[i];
        ev_count_[i] = co_count_[i];
    } else {
        ev_t_[i] = cross;
        ev_partner_[i] = kind;
        ev_count_[i] = 0;
    }
}

void EventDriven::predict(std::int32_t i) {
    advance(i, time_);
    co_t_[i] = kInf;
    co_partner_[i] = -1;
    co_count_[i] = 0;
    scan(i, -1, 0);
    schedule(i);
}

// After a crossing along `axis` in direction `dir`: the collision candidate found so far is
// still the earliest among the partners scanned before (whose trajectories are unchanged, or
// they re-predicted themselves and scanned i), so only the newly adjacent cell layer is
// scanned. A stale candidate (partner collided since) forces a full prediction.
void EventDriven::predict_crossed(std::int32_t i, int axis, int dir) {
    const std::int32_t p = co_partner_[i];
    if (p >= 0 && count_[p] != co_count_[i]) {
        predict(i);
        return;
    }
    scan(i, axis, dir);
    schedule(i);
}

void EventDriven::predict_all() {
    for (std::int32_t i = 0; i < static_cast<std::int32_t>(n_); ++i) predict(i);
}

void EventDriven::heap_up(std::int64_t k) {
    const Node node = heap_[k];
    while (k > 0) {
        const std::int64_t parent = (k - 1) / 2;
        if (!less(node, heap_[parent])) break;
        heap_[k] = heap_[parent];
        pos_in_heap_[heap_[k].i] = static_cast<std::int32_t>(k);
        k = parent;
    }
    heap_[k] = node;
    pos_in_heap_[node.i] = static_cast<std::int32_t>(k);
}

void EventDriven::heap_down(std::int64_t k) {
    const Node node = heap_[k];
    const std::int64_t n = n_;
    while (true) {
        std::int64_t child = 2 * k + 1;
        if (child >= n) break;
        if (child + 1 < n && less(heap_[child + 1], heap_[child])) ++child;
        if (!less(heap_[child], node)) break;
        heap_[k] = heap_[child];
        pos_in_heap_[heap_[k].i] = static_cast<std::int32_t>(k);
        k = child;
    }
    heap_[k] = node;
    pos_in_heap_[node.i] = static_cast<std::int32_t>(k);
}

void EventDriven::heap_update(std::int32_t i) {
    const std::int64_t k = pos_in_heap_[i];
    const double old = heap_[k].t;
    heap_[k].t = ev_t_[i];
    if (ev_t_[i] < old)
        heap_up(k);
    else
        heap_down(k);
}

void EventDriven::heap_build() {
    for (std::int32_t i = 0; i < static_cast<std::int32_t>(n_); ++i) {
        heap_[i] = Node{ev_t_[i], i};
        pos_in_heap_[i] = i;
    }
    for (std::int64_t k = n_ / 2 - 1; k >= 0; --k) heap_down(k);
}

void EventDriven::process_collision(std::int32_t i, std::int32_t j) {
    advance(i, time_);
    advance(j, time_);
    double dr[3];
    image(i, j, time_, dr);
    const double dist = std::sqrt(dot3(dr, dr));
    double n[3] = {dr[0] / dist, dr[1] / dist, dr[2] / dist};
    double e = p_.restitution, beta = p_.beta;
    if (p_.tc > 0.0 && (time_ - last_[i] < p_.tc || time_ - last_[j] < p_.tc)) {
        e = 1.0;
        beta = -1.0;
        ++tc_elastic_;
    }
    last_[i] = last_[j] = time_;
    double* vi = P_[i].v;
    double* vj = P_[j].v;
    double* wi = &w_[3 * i];
    double* wj = &w_[3 * j];
    const double K = p_.inertia_k;
    auto energy = [&]() {
        return 0.5 * m_[i] * (dot3(vi, vi) + K * P_[i].r * P_[i].r * dot3(wi, wi)) +
               0.5 * m_[j] * (dot3(vj, vj) + K * P_[j].r * P_[j].r * dot3(wj, wj));
    };
    const double before = (e < 1.0 || beta > -1.0) ? energy() : 0.0;
    double J[3];
    collide_pair(n, P_[i].r, P_[j].r, m_[i], m_[j], K, e, beta, vi, vj, wi, wj, J);
    if (e < 1.0 || (beta > -1.0 && beta < 1.0)) dissipated_ += before - energy();
    for (int a = 0; a < 3; ++a)
        for (int b = 0; b < 3; ++b) virial_[3 * a + b] += -dr[a] * J[b];
    ++count_[i];
    ++count_[j];
    ++collisions_;
    predict(i);
    heap_update(i);
    predict(j);
    heap_update(j);
}

void EventDriven::process_crossing(std::int32_t i, int axis) {
    advance(i, time_);
    remove_cell(i);
    std::int32_t& c = cell_[3 * i + axis];
    const int v_dir = P_[i].v[axis] > 0.0 ? 1 : -1;
    if (v_dir > 0) {
        if (++c == ncell_[axis]) {
            c = 0;
            P_[i].x[axis] -= p_.box[axis];
        }
    } else {
        if (--c < 0) {
            c = ncell_[axis] - 1;
            P_[i].x[axis] += p_.box[axis];
        }
    }
    insert_cell(i);
    ++crossings_;
    predict_crossed(i, axis, v_dir);
    heap_update(i);
}

bool EventDriven::advance_to(double t, std::int64_t max_events) {
    if (!(t >= time_)) throw std::invalid_argument("advance_to: time must not decrease");
    if (!std::isfinite(t)) throw std::invalid_argument("advance_to: time must be finite");
    const std::int64_t start = collisions_ + crossings_;
    bool reached = true;
    while (true) {
        if (max_events > 0 && collisions_ + crossings_ - start >= max_events) {
            reached = false;
            break;
        }
        const std::int32_t i = heap_[0].i;
        const double et = heap_[0].t;
        if (!(et <= t)) break;
        time_ = et;
        const std::int32_t p = ev_partner_[i];
        if (p >= 0) {
            if (count_[p] != ev_count_[i]) {
                ++invalid_;
                predict(i);
                heap_update(i);
            } else {
                process_collision(i, p);
            }
        } else {
            process_crossing(i, -p - 1);
        }
    }
    if (reached) time_ = t;
    for (std::int32_t i = 0; i < static_cast<std::int32_t>(n_); ++i) advance(i, time_);
    return reached;
}

void EventDriven::positions(double* out) const {
    for (std::int64_t i = 0; i < n_; ++i) {
        const std::int64_t o = order_[i];
        for (int a = 0; a < p_.dim; ++a) {
            const double L = p_.box[a];
            double x = P_[i].x[a] + P_[i].v[a] * (time_ - P_[i].t);
            x -= L * std::floor(x / L);
            if (x >= L) x -= L;
            out[o * p_.dim + a] = x;
        }
    }
}

void EventDriven::velocities(double* out) const {
    for (std::int64_t i = 0; i < n_; ++i)
        for (int a = 0; a < p_.dim; ++a) out[order_[i] * p_.dim + a] = P_[i].v[a];
}

void EventDriven::angular_velocities(double* out) const {
    for (std::int64_t i = 0; i < n_; ++i) {
        const std::int64_t o = order_[i];
        if (p_.dim == 2)
            out[o] = w_[3 * i + 2];
        else
            for (int a = 0; a < 3; ++a) out[3 * o + a] = w_[3 * i + a];
    }
}

double EventDriven::kinetic_energy() const {
    double e = 0.0;
    for (std::int64_t i = 0; i < n_; ++i) e += 0.5 * m_[i] * dot3(P_[i].v, P_[i].v);
    return e;
}

double EventDriven::rotational_energy() const {
    double e = 0.0;
    for (std::int64_t i = 0; i < n_; ++i)
        e += 0.5 * p_.inertia_k * m_[i] * P_[i].r * P_[i].r * dot3(&w_[3 * i], &w_[3 * i]);
    return e;
}

EventDriven::State EventDriven::get_state() const {
    State s;
    s.pos.resize(3 * n_);
    for (std::int64_t i = 0; i < n_; ++i)
        for (int a = 0; a < 3; ++a)
            s.pos[3 * i + a] = P_[i].x[a] + P_[i].v[a] * (time_ - P_[i].t);
    s.vel.resize(3 * n_);
    for (std::int64_t i = 0; i < n_; ++i)
        for (int a = 0; a < 3; ++a) s.vel[3 * i + a] = P_[i].v[a];
    s.omega = w_;
    s.last = last_;
    s.count = count_;
    s.cell = cell_;
    s.ev_time = ev_t_;
    s.ev_partner = ev_partner_;
    s.ev_count = ev_count_;
    s.co_time = co_t_;
    s.co_partner = co_partner_;
    s.co_count = co_count_;
    s.time = time_;
    s.dissipated = dissipated_;
    std::copy(virial_, virial_ + 9, s.virial);
    s.collisions = collisions_;
    s.crossings = crossings_;
    s.invalid = invalid_;
    s.tc_elastic = tc_elastic_;
    return s;
}

void EventDriven::set_state(const State& s) {
    const std::size_t N = static_cast<std::size_t>(n_);
    if (s.pos.size() != 3 * N || s.vel.size() != 3 * N || s.omega.size() != 3 * N ||
        s.last.size() != N || s.count.size() != N || s.cell.size() != 3 * N)
        throw std::invalid_argument("set_state: array sizes do not match this system");
    const bool events = !s.ev_time.empty();
    if (events && (s.ev_time.size() != N || s.ev_partner.size() != N || s.ev_count.size() != N ||
                   s.co_time.size() != N || s.co_partner.size() != N || s.co_count.size() != N))
        throw std::invalid_argument("set_state: event arrays do not match this system");
    if (events)
        for (std::size_t i = 0; i < N; ++i)
            if (s.co_partner[i] < -1 || s.co_partner[i] >= n_ || std::isnan(s.co_time[i]))
                throw std::invalid_argument("set_state: invalid collision candidate");
    if (events)
        for (std::size_t i = 0; i < N; ++i) {
            const std::int32_t p = s.ev_partner[i];
            if (!(p == kNone || (p < 0 && p >= -p_.dim) ||
                  (p >= 0 && p < n_ && p != static_cast<std::int32_t>(i))) ||
                std::isnan(s.ev_time[i]) || s.ev_time[i] < s.time)
                throw std::invalid_argument("set_state: invalid scheduled event");
        }
    for (std::size_t k = 0; k < 3 * N; ++k) {
        const int a = static_cast<int>(k % 3);
        if (s.cell[k] < 0 || s.cell[k] >= ncell_[a])
            throw std::invalid_argument("set_state: cell index out of range");
    }
    for (std::size_t i = 0; i < N; ++i)
        for (int a = 0; a < 3; ++a) {
            P_[i].x[a] = s.pos[3 * i + a];
            P_[i].v[a] = s.vel[3 * i + a];
            P_[i].t = s.time;
        }
    w_ = s.omega;
    last_ = s.last;
    count_ = s.count;
    cell_ = s.cell;
    time_ = s.time;
    dissipated_ = s.dissipated;
    std::copy(s.virial, s.virial + 9, virial_);
    collisions_ = s.collisions;
    crossings_ = s.crossings;
    invalid_ = s.invalid;
    tc_elastic_ = s.tc_elastic;
    build_cells();
    if (events) {
        ev_t_ = s.ev_time;
        ev_partner_ = s.ev_partner;
        ev_count_ = s.ev_count;
        co_t_ = s.co_time;
        co_partner_ = s.co_partner;
        co_count_ = s.co_count;
    } else {
        predict_all();
    }
    heap_build();
}

std::int64_t EventDriven::memory_bytes() const {
    auto b = [](const auto& v) {
        return static_cast<std::int64_t>(v.capacity() * sizeof(v[0]));
    };
    return b(P_) + b(order_) + b(w_) + b(last_) + b(m_) + b(count_) + b(cell_) +
           b(head_) + b(next_) + b(prev_) + b(ev_t_) + b(ev_partner_) + b(ev_count_) +
           b(co_t_) + b(co_partner_) + b(co_count_) +
           b(heap_) + b(pos_in_heap_) + static_cast<std::int64_t>(sizeof(*this));
}

double EventDriven::min_gap() const {
    double best = kInf;
    for (std::int32_t i = 0; i < static_cast<std::int32_t>(n_); ++i) {
        const std::int32_t* ci = &cell_[3 * i];
        const int zr = p_.dim == 3 ? 1 : 0;
        for (int dz = -zr; dz <= zr; ++dz)
            for (int dy = -1; dy <= 1; ++dy)
                for (int dx = -1; dx <= 1; ++dx) {
                    int c[3] = {ci[0] + dx, ci[1] + dy, ci[2] + dz};
                    for (int a = 0; a < 3; ++a) c[a] = (c[a] + ncell_[a]) % ncell_[a];
                    for (std::int32_t j = head_[cell_index(c)]; j >= 0; j = next_[j]) {
                        if (j <= i) continue;
                        double dr[3];
                        image(i, j, time_, dr);
                        best = std::min(best, std::sqrt(dot3(dr, dr)) - P_[i].r - P_[j].r);
                    }
                }
    }
    return best;
}

}  // namespace demstudy::edmd
