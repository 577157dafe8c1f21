// Event-driven molecular dynamics of hard discs (2D) and hard spheres (3D).
// Dimensionless particle units: d = 1, m = 1 (the caller passes diameters and masses).
//
// Milestone 1: fully periodic box (no walls, gravity or shear). Collision rules: constant
// normal restitution e, constant tangential restitution beta (beta = -1: smooth) with the
// reduced moment of inertia K = 4 I / (m d^2) (Lun; Malik 2008 eqs. 2.5-2.11 in the
// reduced-mass form for unequal masses). Inelastic collapse: the TC model (Luding & McNamara
// 1998): a collision in which either partner collided less than tc before is elastic (e = 1,
// no tangential impulse).
//
// Algorithm: cell lists (cells >= the largest diameter, >= 3 per axis) with cell-crossing
// events; one scheduled event per particle held in an indexed binary min-heap keyed by
// (time, particle index); lazy invalidation by per-particle collision counters (a collision
// event stores the partner's counter at prediction); delayed state updates (each particle
// has its own time and is advanced only when it takes part in an event). Vectors are stored
// with 3 components in both dimensions (z = 0 in 2D; the 2D spin is the z component).
#pragma once

#include <cstdint>
#include <limits>
#include <vector>

namespace demstudy::edmd {

struct Params {
    int dim = 3;
    double box[3] = {1.0, 1.0, 1.0};
    double restitution = 1.0;   // e in (0, 1]
    double beta = -1.0;         // tangential restitution in [-1, 1]; -1 = smooth
    double inertia_k = 0.4;     // K = 4 I / (m d^2)
    double tc = 0.0;            // TC model time (0 = off)
};

// Post-collision velocities of one pair (also used by the engine). n points from i to j,
// r_i, r_j are the radii. Returns the impulse J on i (j receives -J).
void collide_pair(const double n[3], double ri, double rj, double mi, double mj,
                  double inertia_k, double e, double beta, double vi[3], double vj[3],
                  double wi[3], double wj[3], double J[3]);

class EventDriven {
public:
    EventDriven(const Params& p, std::int64_t n, const double* pos, const double* vel,
                const double* omega, const double* diameter, const double* mass);

    // Process every event up to time t, then advance all particles to t (scheduled events
    // stay valid: trajectories are unchanged). A state taken at t (get_state, which includes
    // the scheduled events) and restored continues bit-identically: events are processed in
    // the total order (time, particle index), whatever the heap layout. With max_events > 0, stop after that many processed events if t is
    // not reached: everything is then synchronised to the last event time and false returned.
    bool advance_to(double t, std::int64_t max_events = 0);

    double time() const { return time_; }
    std::int64_t size() const { return n_; }
    int dim() const { return p_.dim; }

    // Synchronised accessors (valid after advance_to; positions wrapped into [0, L)).
    void positions(double* out) const;      // (n, dim)
    void velocities(double* out) const;     // (n, dim)
    void angular_velocities(double* out) const;  // (n, 1) in 2D, (n, 3) in 3D
    double kinetic_energy() const;
    double rotational_energy() const;

    std::int64_t collisions() const { return collisions_; }
    std::int64_t cell_crossings() const { return crossings_; }
    std::int64_t events() const { return collisions_ + crossings_; }
    std::int64_t invalid_events() const { return invalid_; }
    std::int64_t elastic_tc_collisions() const { return tc_elastic_; }
    double virial() const { return virial_[0] + virial_[4] + virial_[8]; }
    const double* virial_tensor() const { return virial_; }
    double dissipated() const { return dissipated_; }
    const int* cells_per_axis() const { return ncell_; }

    // Full state for checkpoints (taken after advance_to: all particle times equal time()).
    // Arrays are in the internal (cell-sorted) particle order, which a system built from the
    // same input reproduces; restore only into such a system.
    struct State {
        std::vector<double> pos, vel, omega, last;  // (n,3), (n,3), (n,3), (n,)
        std::vector<std::int64_t> count;           // (n,)
        std::vector<std::int32_t> cell;            // (n,3)
        std::vector<double> ev_time;               // (n,) scheduled event per particle
        std::vector<std::int32_t> ev_partner;      // (n,)
        std::vector<std::int64_t> ev_count;        // (n,)
        std::vector<double> co_time;               // (n,) collision candidate per particle
        std::vector<std::int32_t> co_partner;      // (n,)
        std::vector<std::int64_t> co_count;        // (n,)
        double time = 0.0, dissipated = 0.0, virial[9] = {0};
        std::int64_t collisions = 0, crossings = 0, invalid = 0, tc_elastic = 0;
    };
    State get_state() const;
    void set_state(const State& s);

    // Bytes held by the engine's arrays (capacity of every vector).
    std::int64_t memory_bytes() const;

    // Smallest centre distance minus contact distance over all pairs (negative = overlap).
    double min_gap() const;

private:
    static constexpr double kInf = std::numeric_limits<double>::infinity();
    static constexpr std::int32_t kNone = std::numeric_limits<std::int32_t>::min();

    Params p_;
    std::int64_t n_;
    double time_ = 0.0;
    // what a pair prediction reads, in one cache line: position (at the particle's own time
    // t), velocity, t and radius
    struct alignas(64) Particle {
        double x[3] = {0.0, 0.0, 0.0};
        double v[3] = {0.0, 0.0, 0.0};
        double t = 0.0;
        double r = 0.5;
    };
    std::vector<Particle> P_;
    std::vector<std::int32_t> order_;  // internal index -> input index (cell-sorted order)
    std::vector<double> w_, last_, m_;
    std::vector<std::int64_t> count_;
    std::vector<std::int32_t> cell_;  // per particle 3 cell coordinates
    // cell lists: doubly linked, head per cell
    int ncell_[3] = {1, 1, 1};
    double cw_[3] = {1.0, 1.0, 1.0};
    std::vector<std::int32_t> head_, next_, prev_;
    // scheduled event per particle
    std::vector<double> ev_t_;
    std::vector<std::int32_t> ev_partner_;  // >= 0 collision, -(axis + 1) crossing, kNone
    std::vector<std::int64_t> ev_count_;
    // best collision candidate per particle (kept across its cell crossings)
    std::vector<double> co_t_;
    std::vector<std::int32_t> co_partner_;  // -1: none
    std::vector<std::int64_t> co_count_;
    // indexed min-heap of particles; nodes carry their key so sifting stays in the heap array
    struct Node {
        double t;
        std::int32_t i;
    };
    std::vector<Node> heap_;
    std::vector<std::int32_t> pos_in_heap_;

    std::int64_t collisions_ = 0, crossings_ = 0, invalid_ = 0, tc_elastic_ = 0;
    double virial_[9] = {0};
    double dissipated_ = 0.0;

    std::int64_t cell_index(const std::int32_t* c) const {
        return (static_cast<std::int64_t>(c[2]) * ncell_[1] + c[1]) * ncell_[0] + c[0];
    }
    void insert_cell(std::int32_t i);
    void remove_cell(std::int32_t i);
    void build_cells();
    void advance(std::int32_t i, double t);
    void image(std::int32_t i, std::int32_t j, double tt, double dr[3]) const;
    void predict(std::int32_t i);
    void scan(std::int32_t i, int only_axis, int dir);
    void schedule(std::int32_t i);
    void predict_crossed(std::int32_t i, int axis, int dir);
    void predict_all();
    static bool less(const Node& a, const Node& b) {
        return a.t < b.t || (a.t == b.t && a.i < b.i);
    }
    void heap_up(std::int64_t k);
    void heap_down(std::int64_t k);
    void heap_update(std::int32_t i);
    void heap_build();
    void process_collision(std::int32_t i, std::int32_t j);
    void process_crossing(std::int32_t i, int axis);
};

}  // namespace demstudy::edmd
