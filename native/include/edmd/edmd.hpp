// Event-driven molecular dynamics of hard discs (2D) and hard spheres (3D).
// Dimensionless particle units: d = 1, m = 1, g = 1 when gravity acts (the caller passes
// diameters, masses and the gravity vector).
//
// Physics: free flight, parabolic under a uniform gravity g (pair collision times do not
// depend on g: both partners fall alike); x and z periodic; y periodic (optionally with
// Lees–Edwards sliding images, u = shear_rate · y) or bounded by flat walls normal to y that
// may slide tangentially and move normally at a set speed (the servo sets it between events).
// Collision rules (one Rule for pairs, one per wall): normal restitution constant, Campbell's
// e(v) = ½[1 + exp(−v/v_s)] or Gutt's piecewise c_r = e1 c_b + e2 (c − c_b); tangential:
// constant β with reduced inertia K = 4 I/(m d²) (β = −1 smooth; Lun, Malik 2008 eqs.
// 2.5–2.11), Walton's Coulomb rule (μ, β₀) or, for walls, Campbell's no-slip rule.
// Inelastic collapse: the TC model (Luding & McNamara 1998) for pairs (a collision within tc of
// either partner's previous collision is elastic and smooth) and, for a particle pressed onto a
// wall by gravity, a minimum rebound speed ½ tc |g_n| (it then hops with period tc: "at rest").
//
// Algorithm: cell lists with cell-crossing events (open-ended first and last rows along a
// non-periodic y); one scheduled event per particle in an indexed 4-ary min-heap keyed by
// (time, index) plus one system slot (Lees–Edwards re-scan); lazy invalidation by per-particle
// collision counters; delayed state updates (each particle has its own time). Vectors have 3
// components in both dimensions (z = 0 in 2D; the 2D spin is the z component).
#pragma once

#include <cstddef>
#include <cstdint>
#include <new>
#include <limits>
#include <vector>

namespace demstudy::edmd {

// Allocator of the engine's per-particle arrays: large blocks are advised to use transparent
// huge pages (Linux; the 2 MiB-aligned interior of the block, before first touch, so no extra
// memory). Event-driven access is random in space: with 4 KiB pages a large system misses the
// TLB on most neighbour records, and in a virtual machine every miss is a two-level page walk
// (measured: N = 256 000 ran ~25 % faster with huge pages).
void advise_huge_pages(void* p, std::size_t bytes) noexcept;

template <typename T>
struct HugePageAllocator {
    using value_type = T;
    static constexpr std::size_t kAlign = alignof(T) > 64 ? alignof(T) : 64;
    HugePageAllocator() noexcept = default;
    template <typename U>
    HugePageAllocator(const HugePageAllocator<U>&) noexcept {}
    T* allocate(std::size_t n) {
        void* p = ::operator new(n * sizeof(T), std::align_val_t(kAlign));
        advise_huge_pages(p, n * sizeof(T));
        return static_cast<T*>(p);
    }
    void deallocate(T* p, std::size_t) noexcept { ::operator delete(p, std::align_val_t(kAlign)); }
    template <typename U>
    bool operator==(const HugePageAllocator<U>&) const noexcept { return true; }
    template <typename U>
    bool operator!=(const HugePageAllocator<U>&) const noexcept { return false; }
};
template <typename T>
using big_vector = std::vector<T, HugePageAllocator<T>>;

// One collision law (pairs or one wall).
struct Rule {
    enum Law { kConstant = 0, kCampbellExp = 1, kGutt = 2 };
    enum Tangential { kBeta = 0, kCoulomb = 1, kNoSlip = 2 };
    int law = kConstant;
    double e = 1.0;             // constant e (kConstant)
    double e1 = 1.0, e2 = 1.0;  // Gutt: below / above the crossover speed
    double crossover = 1.0;     // Gutt's c_b
    double speed = 1.0;         // Campbell: e = ½[1 + exp(−g_n/speed)]
    int tangential = kBeta;
    double beta = -1.0;         // kBeta (−1: smooth)
    double mu = 0.0, beta0 = 0.0;  // kCoulomb (Walton)
    bool beta0_from_e = false;     // kCoulomb: β₀ = this collision's e (the default rule)
    // normal restitution at approach speed gn (> 0)
    double restitution(double gn) const;
    // tangential restitution for Walton's rule, given e, K, gn > 0 and |g_t|
    double beta_for(double e, double k, double gn, double gt) const;
};

struct Wall {
    bool present = false;
    double y0 = 0.0, t0 = 0.0;  // position y0 at time t0
    double vn = 0.0;            // normal velocity (servo)
    double u[3] = {0.0, 0.0, 0.0};  // velocity of the wall surface (x, and z in 3D; u[1] unused)
    Rule rule;
    double position(double t) const { return y0 + vn * (t - t0); }
};

struct Params {
    int dim = 3;
    double box[3] = {1.0, 1.0, 1.0};
    Rule pair;                 // pair collisions
    double inertia_k = 0.4;    // K = 4 I / (m d^2)
    double tc = 0.0;           // TC model time (0 = off)
    double gravity[3] = {0.0, 0.0, 0.0};
    bool periodic_y = true;
    double shear_rate = 0.0;   // Lees–Edwards (needs periodic_y)
    Wall wall[2];              // lower, upper (only when !periodic_y)
    double y_lo = 0.0, y_hi = 1.0;  // cell grid along a non-periodic y (first/last rows open)
    // collisional stress per bin along y (0 bins: off)
    std::int64_t stress_bins = 0;
    double stress_lo = 0.0, stress_width = 1.0;
    // bumps of bumpy walls: per particle 0 (mobile), 1 (lower wall's bump), 2 (upper wall's);
    // empty = all mobile. Bumps keep their velocity (the wall's), feel no gravity (under
    // gravity they must be static: a falling particle meets a bump at the first root of a
    // quartic, isolated between its turning points and found by bisection), collide with
    // mobile particles by their wall's rule
    // and count in that wall's impulse and work.
    std::vector<std::int8_t> fixed;
    // collision log: every log_every-th collision, at most log_capacity records (0: off)
    std::int64_t log_every = 0, log_capacity = 0;
};

// What a pair prediction reads, in one cache line: position and velocity at the particle's
// own time t, t and radius.
struct alignas(64) PairRecord {
    double x[3] = {0.0, 0.0, 0.0};
    double v[3] = {0.0, 0.0, 0.0};
    double t = 0.0;
    double r = 0.5;
};

// Collision times (from now) of a particle at xi, vi (time now, radius ri) with the
// candidates P[js[0..n)] of the same image, extrapolated along their flights (gravity g):
// 0 when touching or overlapping and approaching, +inf when they do not meet. AVX2 when the
// CPU has it, with the same bits as the scalar code.
void pair_times(bool gravity, const PairRecord* P, const std::int32_t* js, int n,
                const double* xi, const double* vi, double ri, double now, const double* g,
                double* out);
// Use the AVX2 pair times when the CPU has them (the default); returns whether they are used.
// For tests: both settings give the same bits.
bool set_pair_simd(bool enabled) noexcept;

// Post-collision velocities of one contact. n: unit normal from i to j; im_j = 0 for a wall
// (then vj is the wall's velocity and wj is ignored). Returns the impulse J on i (j gets −J).
void collide(const double n[3], double ri, double rj, double im_i, double im_j,
             double inertia_k, double e, double beta, double vi[3], double vj[3], double wi[3],
             double wj[3], double J[3]);

// One collision log record.
struct LogRecord {
    double time;
    double kind;         // 0 pair, 1 lower wall, 2 upper wall
    double i, j;         // input indices (j = −1 for walls)
    double point[3];     // contact point
    double normal[3];    // from i to j (to the wall)
    double branch[3];    // r_j − r_i (pairs), r_contact − r_i (walls)
    double impulse[3];   // on i
    double velocity[3];  // v_i − v_j before (centres; walls: v_i − u_wall)
    double slip[3];      // contact-point relative velocity g before
};

class EventDriven {
public:
    EventDriven(const Params& p, std::int64_t n, const double* pos, const double* vel,
                const double* omega, const double* diameter, const double* mass);

    // Process every event up to time t, then advance all particles to t. Stops early (state
    // synchronised to the last event time, returns false) after max_events events (> 0; stale
    // predictions count here too) or
    // once the total collision count reaches stop_collisions (> 0).
    bool advance_to(double t, std::int64_t max_events = 0, std::int64_t stop_collisions = 0);

    double time() const { return time_; }
    std::int64_t size() const { return n_; }
    int dim() const { return p_.dim; }
    const Params& params() const { return p_; }

    // Synchronised accessors (valid after advance_to; positions wrapped into the box).
    void positions(double* out) const;      // (n, dim)
    void velocities(double* out) const;     // (n, dim)
    void angular_velocities(double* out) const;  // (n, 1) in 2D, (n, 3) in 3D
    double kinetic_energy() const;
    double rotational_energy() const;

    std::int64_t collisions() const { return collisions_; }
    std::int64_t wall_collisions() const { return wall_collisions_; }
    std::int64_t cell_crossings() const { return crossings_; }
    // every processed event: pair, wall and bump collisions, cell crossings (not the stale
    // predictions discarded, nor the Lees–Edwards re-scans)
    std::int64_t events() const { return collisions_ + wall_collisions_ + crossings_; }
    std::int64_t invalid_events() const { return invalid_; }
    std::int64_t elastic_tc_collisions() const { return tc_elastic_; }
    std::int64_t resting_bounces() const { return resting_; }
    double virial() const { return virial_[0] + virial_[4] + virial_[8]; }
    const double* virial_tensor() const { return virial_; }
    double dissipated() const { return dissipated_; }
    double gravity_work() const { return gravity_work_; }
    // per wall: cumulative impulse received by the particles (3), work done by the wall
    const double* wall_impulse(int side) const { return wall_impulse_[side]; }
    double wall_work(int side) const { return wall_work_[side]; }
    const std::vector<double>& stress_sums() const { return stress_; }  // (bins, 3, 3)
    const int* cells_per_axis() const { return ncell_; }
    double shear_offset() const;  // x offset of the image above (Lees–Edwards), in [0, Lx)

    // Move a wall: position y at the current time, normal velocity vn, surface velocity (x, z).
    // Every prediction is redone (walls change rarely: the servo).
    void set_wall(int side, double y, double vn, double ux, double uz);
    // New collisional-stress bins along y (sums restart from zero).
    void set_stress_bins(double lo, double width, std::int64_t n);
    // Throws std::invalid_argument (prefixed by `who`) unless 0 <= n <= 10^7 is whole and, with
    // bins, the width is finite and positive; lo must be finite.
    static void check_stress_bins(double lo, double width, double n, const char* who);
    static constexpr double kMaxStressBins = 1e7;
    // Scale x positions and the x period by `factor` (servo width scaling), limited so that
    // no pair overlaps; re-predicts. Returns the factor applied.
    double scale_width(double factor);

    // Drain the collision log (records since the last call).
    std::vector<LogRecord> take_log();

    // Full state for checkpoints (taken after advance_to: all particle times equal time()).
    // Arrays are in the internal (cell-sorted) particle order, which a system built from the
    // same input reproduces; restore only into such a system. The collision log is not part
    // of it (drain it before).
    struct State {
        std::vector<double> pos, vel, omega, last;  // (n,3), (n,3), (n,3), (n,)
        std::vector<std::int64_t> count;           // (n,)
        std::vector<std::int32_t> cell;            // (n,3)
        std::vector<double> ev_time;               // (n+1,) scheduled event per particle
        std::vector<std::int32_t> ev_partner;      // (n+1,)
        std::vector<std::int64_t> ev_count;        // (n+1,)
        std::vector<double> co_time;               // (n,) collision candidate per particle
        std::vector<std::int32_t> co_partner;      // (n,)
        std::vector<std::int64_t> co_count;        // (n,)
        std::vector<double> stress;                // (bins * 9)
        // scalars: time, dissipated, gravity work, box x, LE anchor time and cell,
        // walls (y0, t0, vn, ux, uz) x 2, wall impulse 3 x 2, wall work x 2, virial 9
        std::vector<double> scalars;
        std::vector<std::int64_t> counters;  // collisions, crossings, invalid, tc, resting,
                                             // wall collisions, log seen, sorted at
        std::vector<std::int32_t> order;     // internal index -> input index
    };
    State get_state() const;
    void set_state(const State& s);

    // Bytes held by the engine's arrays (capacity of every vector).
    std::int64_t memory_bytes() const;

    // Smallest centre distance minus contact distance over all pairs (negative = overlap).
    double min_gap() const;
    // Smallest distance from a particle surface to a wall (inf without walls; < 0 = inside).
    double min_wall_gap() const;

private:
    static constexpr double kInf = std::numeric_limits<double>::infinity();
    static constexpr std::int32_t kNone = std::numeric_limits<std::int32_t>::min();
    // ev_partner codes below 0: -(axis + 1) crossing upwards, -(axis + 4) downwards, walls,
    // the Lees–Edwards re-scan (system slot)
    static constexpr std::int64_t kSortEvery = 16;  // re-sort memory every 16 N events
    static constexpr std::int32_t kLowerWall = -7, kUpperWall = -8, kReshuffle = -9;

    Params p_;
    std::int64_t n_;
    double time_ = 0.0;
    bool gravity_ = false;
    using Particle = PairRecord;
    big_vector<Particle> P_;
    std::vector<std::int32_t> order_;  // internal index -> input index (cell-sorted order)
    // The bookkeeping an event reads and writes of a particle besides its flight, in one
    // cache line (as separate arrays it was ~10 lines per particle: measured 19-32 % fewer
    // last-level misses, up to 20 % faster at N = 256 000). Entry n_ is the system slot
    // (ev_partner and pos_in_heap only).
    struct alignas(64) Book {
        double co_t = kInf;  // collision candidate: time, the partner's collision count then,
        std::int64_t co_count = 0;
        std::int64_t count = 0;   // collisions so far (lazy invalidation)
        double last = -kInf;      // time of the last collision (TC model)
        std::int32_t co_partner = -1;     // and the partner (-1: none)
        std::int32_t ev_partner = kNone;  // scheduled event: a partner or an event code
        std::int32_t pos_in_heap = 0;
        std::int32_t cell[3] = {0, 0, 0};
        std::int8_t fixed = 0;  // 0 mobile, 1/2 bump of the lower/upper wall
    };
    big_vector<Book> book_;
    struct alignas(32) Spin {  // angular velocity and mass: what a collision reads besides
        double w[3] = {0.0, 0.0, 0.0};  // angular velocity
        double m = 1.0;
    };
    big_vector<Spin> spin_;
    bool has_bumps_ = false;
    const double* grav(std::int32_t i) const {
        static constexpr double none[3] = {0.0, 0.0, 0.0};
        return book_[i].fixed != 0 ? none : p_.gravity;
    }
    int ncell_[3] = {1, 1, 1};
    double cw_[3] = {1.0, 1.0, 1.0};
    double org_[3] = {0.0, 0.0, 0.0};  // lower edge of the cell grid
    double dmax_ = 1.0;
    big_vector<std::int32_t> head_, next_, prev_;
    struct Node {
        double t;
        std::int32_t i;
    };
    // A 4-ary heap: the children 4k+1 … 4k+4 of node k share one 64-byte line (the array
    // starts kHeapPad nodes early, so index 4k+1 is line-aligned), and the tree is half as deep
    // as a binary heap: fewer moves, so fewer writes to the random book entries (pos_in_heap).
    static constexpr std::int64_t kArity = 4, kHeapPad = 3;
    big_vector<Node> heap_;
    Node& node_at(std::int64_t k) { return heap_[static_cast<std::size_t>(k + kHeapPad)]; }
    const Node& node_at(std::int64_t k) const {
        return heap_[static_cast<std::size_t>(k + kHeapPad)];
    }
    // Lees–Edwards: images above are shifted by delta(t) = anchor_cell * cw_x + rate Ly (t - t_a)
    double le_t_ = 0.0;
    std::int32_t le_cell_ = 0;

    std::int64_t collisions_ = 0, crossings_ = 0, invalid_ = 0, tc_elastic_ = 0, resting_ = 0;
    std::int64_t wall_collisions_ = 0, log_seen_ = 0, sorted_at_ = 0;
    double virial_[9] = {0};
    double dissipated_ = 0.0, gravity_work_ = 0.0;
    double wall_impulse_[2][3] = {{0, 0, 0}, {0, 0, 0}};
    double wall_work_[2] = {0.0, 0.0};
    std::vector<double> stress_;
    std::vector<LogRecord> log_;

    // Cells are numbered row by row (x fastest): an interior cell's neighbours are at fixed
    // index offsets (nb_off_), the fast path of the neighbour scan. Particles are stored in
    // Morton order of their cells instead (neighbours close in memory along every axis).
    std::int64_t cell_index(const std::int32_t* c) const {
        return (static_cast<std::int64_t>(c[2]) * ncell_[1] + c[1]) * ncell_[0] + c[0];
    }
    // nb_off_[list][k]: list 0 all neighbour cells, list 1 + 2 axis + (dir > 0) the layer at
    // offset dir along axis (what a crossing uncovers)
    std::int64_t nb_off_[7][27] = {{0}};
    int n_nb_[7] = {0};
    void setup_grid();
    int cell_of(double x, int axis) const;
    void insert_cell(std::int32_t i);
    void remove_cell(std::int32_t i);
    void build_cells();
    void advance(std::int32_t i, double t);
    void state_at(std::int32_t i, double tt, double x[3], double v[3]) const;
    double le_delta(double t) const;
    bool le_row(std::int32_t i) const {
        return p_.shear_rate != 0.0 && (book_[i].cell[1] == 0 || book_[i].cell[1] == ncell_[1] - 1);
    }
    void separation(std::int32_t i, std::int32_t j, double dr[3], double dv[3]) const;
    void predict(std::int32_t i);
    void scan(std::int32_t i, int only_axis, int dir);
    template <typename F>
    void for_neighbours(std::int32_t i, int only_axis, int dir, F&& visit) const;
    void schedule(std::int32_t i);
    double next_boundary(std::int32_t i, std::int32_t& kind) const;
    double wall_time(std::int32_t i, int side) const;
    void predict_crossed(std::int32_t i, int axis, int dir);
    void predict_rows();
    void predict_all();
    void schedule_system();
    static bool less(const Node& a, const Node& b) {
        return a.t < b.t || (a.t == b.t && a.i < b.i);
    }
    void heap_up(std::int64_t k);
    void heap_down(std::int64_t k);
    void heap_update(std::int32_t i);
    void heap_build();
    void add_stress(double yi, double yj, const double dr[3], const double J[3]);
    void log_collision(int kind, std::int32_t i, std::int32_t j, const double point[3],
                       const double n[3], const double branch[3], const double J[3],
                       const double v[3], const double g[3]);
    void process_collision(std::int32_t i, std::int32_t j);
    void process_wall(std::int32_t i, int side);
    void process_bump(std::int32_t i, std::int32_t b);
    void body_contact(std::int32_t i, int side, const double n[3], const double u[3],
                      bool tc_model, std::int32_t partner, bool apply_rule = true);
    void rebound_floor(const double n[3], const double u[3], double m, double v[3], double J[3]);
    void process_crossing(std::int32_t i, int axis);
    void process_reshuffle();
    void reorder();
    void sort_by_cell(std::vector<std::int32_t>& perm) const;
};

}  // namespace demstudy::edmd
