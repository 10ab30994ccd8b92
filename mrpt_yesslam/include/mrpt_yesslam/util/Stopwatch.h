#pragma once
// Stage timings: every stage measures with the steady clock (never the wall clock, which jumps).
#include <chrono>

namespace mrpt_yesslam
{
/** The clock every stage time is measured with. */
using SteadyClock = std::chrono::steady_clock;

/** Milliseconds since `t0` on the steady clock. */
inline double msSince(SteadyClock::time_point t0) { return std::chrono::duration<double, std::milli>(SteadyClock::now() - t0).count(); }
}  // namespace mrpt_yesslam
