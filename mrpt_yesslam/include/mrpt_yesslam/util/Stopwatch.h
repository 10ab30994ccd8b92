#pragma once
// Stage timings: every stage measures with the steady clock (never the wall clock, which jumps).
#include <chrono>
#include <ctime>
#include <map>
#include <string>

namespace mrpt_yesslam
{
/** The clock every stage time is measured with. */
using SteadyClock = std::chrono::steady_clock;

/** Milliseconds since `t0` on the steady clock. */
inline double msSince(SteadyClock::time_point t0)
{
	return std::chrono::duration<double, std::milli>(SteadyClock::now() - t0).count();
}

/** CPU time the calling thread has used, in ms. A stage's wall time also counts the time its thread
 * waited for a core: on two cores shared by the frame, detector, reader, mapping and dense threads
 * the wall time of a stage is up to twice its work, which the "_cpu" stages (stats.json) give.
 * Only the calling thread's: work handed to OpenCV's or Ceres' helper threads is not in it. */
inline double threadCpuMs()
{
	timespec ts{};
	clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
	return static_cast<double>(ts.tv_sec) * 1e3 + static_cast<double>(ts.tv_nsec) * 1e-6;
}

/** A stage's two clocks, started together: the wall time it took and its thread's CPU time. */
struct TStageClock
{
	SteadyClock::time_point wall = SteadyClock::now();
	double cpu = threadCpuMs();

	double wallMs() const { return msSince(wall); }
	double cpuMs() const { return threadCpuMs() - cpu; }
	/** Adds the time since the start to `ms[stage]` and the CPU time to `ms[stage + "_cpu"]`. */
	void addTo(std::map<std::string, double>& ms, const std::string& stage) const
	{
		ms[stage] += wallMs();
		ms[stage + "_cpu"] += cpuMs();
	}
};
}  // namespace mrpt_yesslam
