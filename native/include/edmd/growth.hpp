// Lubachevsky–Stillinger growth: a fluid packing of hard discs (2D) or spheres (3D) made by
// growing the diameters of a dilute random state in an event-driven run.
// Dimensionless particle units: d = 1, m = 1 (the caller passes the final diameters).
//
// Every diameter is s(t) d_i with a common scale s(t) = s0 + rate t (so a polydisperse set
// keeps its size ratios). Free flight (no gravity); x and z periodic, y periodic or bounded by
// two flat, fixed walls whose surfaces are at y_lo and y_hi. Collisions are elastic and
// smooth in the frame of the growing surfaces: the normal relative velocity u (positive when
// separating) becomes 2 A rate − u, A the contact distance at s = 1 (pairs: (d_i + d_j)/2,
// walls: d_i/2), so a growing pair always separates. Growth heats the system: after each
// chunk of time the velocities are rescaled to the temperature T (kinetic, per degree of
// freedom). After growth an elastic run at s = s_end (rate 0) relaxes the packing.
//
// Algorithm: a cell grid of width >= the largest final diameter (periodic lengths >= 2 d_max;
// with 1 or 2 cells along an axis every image is visited), cell-crossing
// events, one scheduled event per particle in a binary heap with lazy invalidation (per
// particle version of its own prediction, collision counter of the partner).
#pragma once

#include <cstdint>
#include <stdexcept>

namespace demstudy::edmd {

struct GrowthParams {
    int dim = 3;
    double box[3] = {1.0, 1.0, 1.0};
    bool periodic_y = true;
    double y_lo = 0.0, y_hi = 1.0;  // wall surfaces (only when !periodic_y)
    double s_start = 0.5, s_end = 1.0;
    double rate = 0.05;          // ds/dt
    double relax_time = 0.0;     // elastic run at s_end after the growth
    double chunk = 0.25;         // time between velocity rescalings
    double temperature = 1.0;    // rescaling target (kinetic, per degree of freedom)
    std::int64_t max_events = 0; // 0: no cap
};

struct GrowthResult {
    bool reached = false;        // s_end reached and the relaxation done within max_events
    double scale = 0.0;          // s at the end
    std::int64_t collisions = 0; // pair and wall collisions
    std::int64_t events = 0;     // every processed event (collisions and crossings)
    double time = 0.0;
    // virial pressure during the relaxation: sum over pair collisions of m_ij Δu r_ij·n
    // (the caller divides by dim V t)
    double relax_virial = 0.0;
};

// Positions (n, 3) are read at s = s_start (no overlap, inside the walls) and overwritten by
// the final ones (wrapped into the box); velocities (n, 3) likewise. Throws
// std::invalid_argument for a box too small for the grid or an overlapping start.
GrowthResult grow_packing(const GrowthParams& p, std::int64_t n, double* pos, double* vel,
                          const double* diameter, const double* mass);

}  // namespace demstudy::edmd
