// The step of Gutt's (1989) lattice grain dynamics (LGD), bit-identical to the numpy
// reference demstudy/engines/lgd/reference.py (which documents every semantic choice).
// Units: the listing's integers (offsets idl/4096, velocities 1/256 cm/s, ticks 1/65536 s);
// demstudy's dimensionless particle units (d = 1, m = 1, g = 1) apply above this core.
#pragma once

#include <cstdint>

namespace demstudy::lgd {

// The listing's derived constants (reference.Derived), plus nw (extra wall particles).
struct Params {
    std::int64_t idl, id, idx, idy, id2, icb, icp, icw, iep1, iep2, iew1, iew2;
    std::int64_t ke, ke1, ke2, kx, ky, kq, kxp, kxw, kqp, kqw, igx, igy, ntu, itm, nw;
    double gm, gm2, dl3, dy1, dy3;
};

// The lattice arrays (row-major (nyt, nxt), array row r = Gutt's R - 1, column c = G - 1)
// and the scalars carried between steps.
struct State {
    std::int8_t* mlp;
    std::int64_t *ipx, *ipy, *ivx, *ivy;
    std::int32_t* nlp;
    std::int64_t nxt, nyt;
    std::int64_t pv2, pvx, pvy;  // the previous step's peak-speed grain
    std::int64_t nn, itt;        // number of the next step, elapsed ticks
};

// nn it itt sum_vx sum_vy sum_v2 peak_v2 is1 ip1 is2 ip2 is3 ip3 nq (lattice.STEP_LOG_FIELDS)
constexpr int kLogFields = 14;

std::int64_t time_step(const Params& p, std::int64_t pv2, std::int64_t pvx, std::int64_t pvy);

// Advance n_steps steps in place; log has room for n_steps * kLogFields values.
void run_steps(const Params& p, State& s, std::int64_t n_steps, std::int64_t* log);

}  // namespace demstudy::lgd
