#include "mrpt_yesslam/io/Association.h"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <tuple>

namespace mrpt_yesslam
{
namespace
{
struct Candidate
{
	double diff;
	double a, b;
	std::size_t ia, ib;
	bool operator<(const Candidate& o) const
	{
		return std::tie(diff, a, b, ia, ib) < std::tie(o.diff, o.a, o.b, o.ia, o.ib);
	}
};

std::vector<std::pair<std::size_t, std::size_t>> greedy(std::vector<Candidate>& cands, const std::vector<double>& first,
														std::size_t nFirst, std::size_t nSecond)
{
	std::sort(cands.begin(), cands.end());
	std::vector<char> usedA(nFirst, 0), usedB(nSecond, 0);
	std::vector<std::pair<std::size_t, std::size_t>> out;
	for (const auto& c : cands)
	{
		if (usedA[c.ia] || usedB[c.ib]) continue;
		usedA[c.ia] = usedB[c.ib] = 1;
		out.emplace_back(c.ia, c.ib);
	}
	std::sort(out.begin(), out.end(),
			  [&](const auto& x, const auto& y)
			  { return std::tie(first[x.first], x.first) < std::tie(first[y.first], y.first); });
	return out;
}
}  // namespace

std::vector<std::pair<std::size_t, std::size_t>> associateTimestamps(const std::vector<double>& first,
																	 const std::vector<double>& second, double offset,
																	 double maxDiff)
{
	// Sort `second` by b + offset, then for each a scan the window around a. The window bounds are
	// widened by a tiny slack and every candidate is re-tested with the exact expression of
	// associate.py, so rounding cannot change the candidate set.
	std::vector<std::size_t> order(second.size());
	std::iota(order.begin(), order.end(), 0);
	std::vector<double> shifted(second.size());
	for (std::size_t i = 0; i < second.size(); i++) shifted[i] = second[i] + offset;
	std::sort(order.begin(), order.end(), [&](std::size_t x, std::size_t y) { return shifted[x] < shifted[y]; });
	std::vector<double> sortedShifted(order.size());
	for (std::size_t k = 0; k < order.size(); k++) sortedShifted[k] = shifted[order[k]];

	std::vector<Candidate> cands;
	for (std::size_t ia = 0; ia < first.size(); ia++)
	{
		const double a = first[ia];
		const double slack = 1e-9 * (1.0 + std::abs(a));
		auto lo = std::lower_bound(sortedShifted.begin(), sortedShifted.end(), a - maxDiff - slack);
		for (auto it = lo; it != sortedShifted.end() && *it <= a + maxDiff + slack; ++it)
		{
			const std::size_t ib = order[static_cast<std::size_t>(it - sortedShifted.begin())];
			const double d = std::abs(a - (second[ib] + offset));
			if (d < maxDiff) cands.push_back({d, a, second[ib], ia, ib});
		}
	}
	return greedy(cands, first, first.size(), second.size());
}

std::vector<std::pair<std::size_t, std::size_t>> associateTimestampsQuadratic(const std::vector<double>& first,
																			  const std::vector<double>& second,
																			  double offset, double maxDiff)
{
	std::vector<Candidate> cands;
	for (std::size_t ia = 0; ia < first.size(); ia++)
		for (std::size_t ib = 0; ib < second.size(); ib++)
		{
			const double d = std::abs(first[ia] - (second[ib] + offset));
			if (d < maxDiff) cands.push_back({d, first[ia], second[ib], ia, ib});
		}
	return greedy(cands, first, first.size(), second.size());
}
}  // namespace mrpt_yesslam
