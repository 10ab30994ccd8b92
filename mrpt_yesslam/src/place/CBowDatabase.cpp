#include "mrpt_yesslam/place/CBowDatabase.h"

#include <algorithm>

#include "mrpt_yesslam/data/CSparseMap.h"
#include "mrpt_yesslam/place/CVocabulary.h"

#include <map>
#include <set>

namespace mrpt_yesslam
{
namespace
{
void removeId(std::vector<TKeyFrameId>& v, TKeyFrameId id)
{
	v.erase(std::remove(v.begin(), v.end(), id), v.end());
}
}  // namespace

void CBowDatabase::add(TKeyFrameId id, std::shared_ptr<const TBow> bow)
{
	if (!bow) return;
	std::lock_guard lk(mtx_);
	if (const auto it = bows_.find(id); it != bows_.end())
		for (const auto& [w, x] : it->second->words) removeId(index_.at(w), id);
	for (const auto& [w, x] : bow->words) index_.at(w).push_back(id);
	bows_[id] = std::move(bow);
}

bool CBowDatabase::erase(TKeyFrameId id)
{
	std::lock_guard lk(mtx_);
	const auto it = bows_.find(id);
	if (it == bows_.end()) return false;
	for (const auto& [w, x] : it->second->words) removeId(index_[w], id);
	bows_.erase(it);
	return true;
}

std::size_t CBowDatabase::size() const
{
	std::lock_guard lk(mtx_);
	return bows_.size();
}

std::shared_ptr<const TBow> CBowDatabase::bow(TKeyFrameId id) const
{
	std::lock_guard lk(mtx_);
	const auto it = bows_.find(id);
	return it == bows_.end() ? nullptr : it->second;
}

std::vector<TBowCandidate> CBowDatabase::query(const TBowVector& q, const std::set<TKeyFrameId>& exclude,
											   double minCommonRatio, std::size_t minCommonWords) const
{
	std::lock_guard lk(mtx_);
	std::unordered_map<TKeyFrameId, std::size_t> common;
	for (const auto& [w, x] : q)
		if (w < index_.size())
			for (const auto id : index_[w])
				if (!exclude.count(id)) common[id]++;
	std::size_t most = 0;
	for (const auto& [id, n] : common) most = std::max(most, n);
	const auto need = std::max(minCommonWords, static_cast<std::size_t>(minCommonRatio * static_cast<double>(most)));
	std::vector<TBowCandidate> out;
	for (const auto& [id, n] : common)
		if (n >= need) out.push_back({id, n, CVocabulary::score(q, bows_.at(id)->words)});
	std::sort(out.begin(), out.end(),
			  [](const auto& a, const auto& b)
			  { return a.score != b.score ? a.score > b.score : a.keyFrame < b.keyFrame; });
	return out;
}

std::vector<TBowCandidate> groupCandidates(const std::vector<TBowCandidate>& cands, const CSparseMap& map,
										   std::size_t neighbours, double keepRatio)
{
	std::map<TKeyFrameId, const TBowCandidate*> byId;
	for (const auto& c : cands) byId[c.keyFrame] = &c;
	std::vector<TBowCandidate> groups;
	double best = 0;
	for (const auto& c : cands)
	{
		if (!map.hasKeyFrame(c.keyFrame) || map.isBad(c.keyFrame)) continue;
		TBowCandidate g = c;
		g.groupScore = c.score;
		for (const auto n : map.covisible(c.keyFrame, neighbours))
			if (const auto it = byId.find(n); it != byId.end())
			{
				g.groupScore += it->second->score;
				if (it->second->score > g.score)
					g.keyFrame = n, g.score = it->second->score, g.commonWords = it->second->commonWords;
			}
		best = std::max(best, g.groupScore);
		groups.push_back(g);
	}
	std::vector<TBowCandidate> out;
	std::set<TKeyFrameId> taken;
	std::sort(groups.begin(), groups.end(),
			  [](const auto& a, const auto& b)
			  { return a.groupScore != b.groupScore ? a.groupScore > b.groupScore : a.keyFrame < b.keyFrame; });
	for (const auto& g : groups)
		if (g.groupScore >= keepRatio * best && taken.insert(g.keyFrame).second) out.push_back(g);
	return out;
}
}  // namespace mrpt_yesslam
