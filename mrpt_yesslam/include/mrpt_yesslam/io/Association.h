#pragma once
// Timestamp association exactly as the TUM benchmark's associate.py does it: every pair with
// |a - (b + offset)| < maxDiff is a candidate; candidates are taken greedily by increasing
// difference (ties by a, then b), each stamp at most once; the result is in order of a.
// We find the candidates with a sliding window over sorted stamps instead of the quadratic
// double loop, which gives the same candidate set and hence the same matches.
#include <cstddef>
#include <utility>
#include <vector>

namespace mrpt_yesslam
{
/** Index pairs (into `first`, into `second`) matched as associate.py matches them, sorted by
 * first[i]. Inputs need not be sorted; duplicate stamps are allowed (each index is used once). */
std::vector<std::pair<std::size_t, std::size_t>> associateTimestamps(const std::vector<double>& first,
																	 const std::vector<double>& second,
																	 double offset = 0.0, double maxDiff = 0.02);

/** The reference O(N*M) greedy association, literally as associate.py; for tests and checks. */
std::vector<std::pair<std::size_t, std::size_t>> associateTimestampsQuadratic(const std::vector<double>& first,
																			  const std::vector<double>& second,
																			  double offset = 0.0,
																			  double maxDiff = 0.02);
}  // namespace mrpt_yesslam
