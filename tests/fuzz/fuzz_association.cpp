// Differential fuzz target: the fast association must equal associate.py's quadratic greedy for
// any stamps, offsets and windows (aborts on a difference, which libFuzzer reports as a crash).
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <vector>

#include "mrpt_yesslam/io/Association.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size)
{
	using namespace mrpt_yesslam;
	if (size < 4) return 0;
	// Byte 0: how many stamps go to the first list; byte 1: window; byte 2: offset; rest: stamps as
	// 16-bit steps of 1 ms on top of a TUM-like epoch (so that ties and near-ties are common).
	const std::size_t n = (size - 3) / 2;
	const std::size_t na = n ? data[0] % (n + 1) : 0;
	const double maxDiff = 0.001 * (1 + data[1] % 60);
	const double offset = 0.001 * (static_cast<int>(data[2]) - 128);
	std::vector<double> a, b;
	for (std::size_t i = 0; i < n && i < 400; i++)
	{
		uint16_t v;
		std::memcpy(&v, data + 3 + 2 * i, 2);
		(i < na ? a : b).push_back(1305031102.0 + 0.001 * v);
	}
	if (associateTimestamps(a, b, offset, maxDiff) != associateTimestampsQuadratic(a, b, offset, maxDiff)) std::abort();
	return 0;
}
