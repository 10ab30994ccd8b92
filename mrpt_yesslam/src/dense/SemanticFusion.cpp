#include "mrpt_yesslam/dense/SemanticFusion.h"

#include <algorithm>
#include <cmath>

namespace mrpt_yesslam
{
void TLabelBelief::observe(TSemLabel l, double p, int numLabels)
{
	p = std::clamp(p, 1e-6, 1 - 1e-6);
	const double other = std::log((1 - p) / std::max(1, numLabels - 1));
	// Every class gets log((1-p)/(K-1)); the observed one log p instead, i.e. the difference extra.
	base += other;
	const double gain = std::log(p) - other;
	auto it = std::find_if(extra.begin(), extra.end(), [&](const auto& e) { return e.first == l; });
	if (it == extra.end())
		extra.emplace_back(l, gain);
	else
		it->second += gain;
	observations++;
}

void TLabelBelief::merge(const TLabelBelief& o)
{
	base += o.base;
	for (const auto& [l, g] : o.extra)
	{
		// (A structured binding is captured by copy: C++17 lets no lambda capture it by reference.)
		auto it = std::find_if(extra.begin(), extra.end(), [l = l](const auto& e) { return e.first == l; });
		if (it == extra.end())
			extra.emplace_back(l, g);
		else
			it->second += g;
	}
	observations += o.observations;
}

double TLabelBelief::probability(TSemLabel l, int numLabels) const
{
	// Z = sum over labels of exp(evidence - base): unseen labels contribute 1 each.
	double z = static_cast<double>(numLabels - static_cast<int>(extra.size())), top = 0;
	for (const auto& e : extra) top = std::max(top, e.second);
	// Scaled by exp(-top) against overflow after many observations.
	z *= std::exp(-top);
	double mine = std::exp(-top);
	for (const auto& e : extra)
	{
		const double v = std::exp(e.second - top);
		z += v;
		if (e.first == l) mine = v;
	}
	return mine / z;
}

std::pair<TSemLabel, double> TLabelBelief::best(int numLabels) const
{
	if (extra.empty()) return {0, 1.0 / std::max(1, numLabels)};
	auto it =
		std::max_element(extra.begin(), extra.end(), [](const auto& a, const auto& b) { return a.second < b.second; });
	// A label observed only against the evidence (p < 0.5 of a 2-label world) could be below base.
	if (it->second < 0)
	{
		for (int l = 0; l < numLabels; l++)
			if (std::none_of(extra.begin(), extra.end(), [&](const auto& e) { return e.first == l; }))
				return {static_cast<TSemLabel>(l), probability(static_cast<TSemLabel>(l), numLabels)};
	}
	return {it->first, probability(it->first, numLabels)};
}
}  // namespace mrpt_yesslam
