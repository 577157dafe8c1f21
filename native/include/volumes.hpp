// Exact particle/bin overlap volumes for volume-weighted (= mass-weighted) binning.
//
// Dimensionless particle units: diameter d = 1, mass m = 1. All lengths are in diameters.
// "Volume" means area for discs (dim = 2) and volume for spheres (dim = 3). The binning
// axis is one Cartesian axis; bins are the strips/slabs lo + b*width <= y < lo + (b+1)*width.
#pragma once

#include <cstdint>

namespace demstudy {

// Part of a disc (radius r) whose signed offset from the centre along the axis is <= s:
// the circular-segment area r^2 (pi/2 + asin(s/r)) + s sqrt(r^2 - s^2), clamped to [0, pi r^2].
double disc_cumulative_area(double s, double r) noexcept;

// Part of a sphere (radius r) with offset <= s: the cap volume pi h^2 (3r - h) / 3, h = r + s.
double sphere_cumulative_volume(double s, double r) noexcept;

// Area of the disc centred at c (along the axis) inside the strip lo <= y <= hi.
double disc_strip_area(double c, double r, double lo, double hi) noexcept;

// Volume of the sphere centred at c (along the axis) inside the slab lo <= y <= hi.
double sphere_slab_volume(double c, double r, double lo, double hi) noexcept;

// Overlap of every particle with one strip/slab: out[i] = |particle i  cap [lo, hi]|.
void strip_overlaps(const double* coord, const double* radius, std::int64_t n, double lo,
                    double hi, int dim, double* out) noexcept;

// For each particle i and bin b, add the exact overlap V_ib to out_volume[b] and
// V_ib * values[i, :] to out_sums[b, :] (row-major, nvalues columns).
// period > 0: the axis is periodic with that period (images at c + k*period all count);
// period == 0: the parts of a particle outside [lo, lo + nbins*width] are dropped.
// Particles with a non-finite coordinate or a non-finite/negative radius are skipped;
// the return value is how many were skipped.
std::int64_t accumulate_bins(const double* coord, const double* radius, const double* values,
                             std::int64_t n, std::int64_t nvalues, double lo, double width,
                             std::int64_t nbins, int dim, double period, double* out_volume,
                             double* out_sums) noexcept;

// Number of profile value columns F for dim 2 (10) or 3 (18); see accumulate_profile.
int profile_nvalues(int dim) noexcept;

// accumulate_bins with the per-particle values built on the fly from the velocity (N, dim)
// and angular velocity (N, n_rot; n_rot = 1 in 2D, 3 in 3D). Columns of out_sums:
//   v_a (dim) | v_a v_b for a <= b in row-major order (dim(dim+1)/2) | w_a (n_rot)
//   | j w_a (n_rot) | j |w|^2 | j | 1/V,  with j = inertia_factor * r^2 = I / m and V the
// particle volume (so the 1/V column sums to the fractional particle count of a bin).
std::int64_t accumulate_profile(const double* coord, const double* radius,
                                const double* velocity, const double* omega, std::int64_t n,
                                double inertia_factor, double lo, double width,
                                std::int64_t nbins, int dim, double period, double* out_volume,
                                double* out_sums) noexcept;

// Kernel instruction set in use: "x86-64-v3" (AVX2 + FMA build, chosen at run time when the
// CPU supports it) or "baseline".
const char* simd_variant() noexcept;

// Allow (true, the default) or forbid the x86-64-v3 kernels, e.g. to compare the two builds;
// returns the variant now in use.
const char* set_simd(bool enabled) noexcept;

}  // namespace demstudy
