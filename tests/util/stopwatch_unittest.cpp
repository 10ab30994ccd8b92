// The stage clocks: a thread's CPU time counts its work and not the time it waited.
#include <gtest/gtest.h>

#include <chrono>
#include <thread>

#include "mrpt_yesslam/util/Stopwatch.h"

using namespace mrpt_yesslam;

TEST(Stopwatch, AThreadsCpuTimeCountsItsWorkAndNotItsWaiting)
{
	// The "_cpu" stages of stats.json tell a slow stage from one that waited for a shared core.
	const auto t0 = SteadyClock::now();
	double c0 = threadCpuMs();
	std::this_thread::sleep_for(std::chrono::milliseconds(60));
	const double sleptCpu = threadCpuMs() - c0, sleptWall = msSince(t0);
	EXPECT_GE(sleptWall, 60.0);
	EXPECT_LT(sleptCpu, 10.0) << "sleeping is no work";

	// Work until the thread has used 20 ms of CPU (however long a loaded machine makes that take,
	// up to 10 s): the wall time it took can only be longer.
	const auto t1 = SteadyClock::now();
	c0 = threadCpuMs();
	volatile double x = 0;
	while (threadCpuMs() - c0 < 20 && msSince(t1) < 10000)
		for (int i = 0; i < 1000; i++) x = x + 1e-9 * i;
	const double busyCpu = threadCpuMs() - c0, busyWall = msSince(t1);
	EXPECT_GE(busyCpu, 20.0) << "a busy loop is work";
	EXPECT_LE(busyCpu, busyWall * 1.002 + 0.1) << "one thread cannot work longer than it was timed";
}
