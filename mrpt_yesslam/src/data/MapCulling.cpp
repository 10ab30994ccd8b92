#include "MapCulling.h"

#include <algorithm>

namespace mrpt_yesslam::sparse_map
{
namespace
{
// Points created by one keyframe stay on the recent list for this many further keyframes
// (ORB-SLAM2's MapPointCulling judges a point until three keyframes after its creation).
constexpr TKeyFrameId kRecentKeyFrames = 3;
}  // namespace

std::size_t countTracking(TSparseMapStore& s, const std::vector<TPointId>& visible, const std::vector<TPointId>& found,
						  const std::vector<TPointId>& seenThrough, int seeThroughFrames)
{
	for (TPointId id : visible)
		if (auto it = s.points.find(id); it != s.points.end()) it->second.visible++;
	for (TPointId id : found)
		if (auto it = s.points.find(id); it != s.points.end())
		{
			it->second.found++;
			it->second.seenThrough = 0;
		}
	std::size_t erased = 0;
	for (TPointId id : seenThrough)
	{
		auto it = s.points.find(id);
		if (it == s.points.end() || it->second.bad) continue;
		CMapPoint& p = it->second;
		if (seeThroughFrames <= 0 || ++p.seenThrough < seeThroughFrames) continue;
		s.dropPoint(p);
		erased++;
	}
	if (erased) s.reorderDirty();
	return erased;
}

std::size_t cullRecentPoints(TSparseMapStore& s, TKeyFrameId currentKf, double minFoundRatio,
							 std::size_t minObservations)
{
	std::size_t culled = 0;
	std::deque<TPointId> keep;
	for (TPointId id : s.recent)
	{
		auto it = s.points.find(id);
		if (it == s.points.end() || it->second.bad) continue;  // already gone: leaves the list
		CMapPoint& p = it->second;
		const double ratio = static_cast<double>(p.found) / std::max(1, p.visible);
		const bool tooRare = ratio < minFoundRatio;
		const bool tooFewViews = currentKf >= p.firstKeyFrame + 2 && p.observations.size() < minObservations;
		if (tooRare || tooFewViews)
		{
			s.dropPoint(p);
			culled++;
			continue;
		}
		// Survived its trial period: a grown-up point, no longer judged (ORB-SLAM2).
		if (currentKf < p.firstKeyFrame + kRecentKeyFrames) keep.push_back(id);
	}
	s.recent.swap(keep);
	s.reorderDirty();
	return culled;
}

std::vector<TKeyFrameId> cullRedundantKeyFrames(TSparseMapStore& s, TKeyFrameId currentKf, double redundantRatio,
												std::size_t minOtherObservers, double maxDepth)
{
	std::vector<TKeyFrameId> erased;
	const auto cit = s.keyFrames.find(currentKf);
	if (cit == s.keyFrames.end() || cit->second->bad) return erased;
	const std::vector<TKeyFrameId> local = cit->second->orderedConnections;
	for (TKeyFrameId id : local)
	{
		auto it = s.keyFrames.find(id);
		if (it == s.keyFrames.end()) continue;
		CKeyFrame& kf = *it->second;
		// A keyframe that closes a loop stays (ORB-SLAM2's SetNotErase): erased, its loop edge would
		// leave the essential graph, and a later pose graph would lose the loop without a word; so
		// does one the loop stage is working on (pinned from its queueing to its correction).
		if (kf.bad || !kf.parent || id == currentKf || !kf.loopEdges.empty() || kf.pinned > 0) continue;
		std::size_t numPoints = 0, redundant = 0;
		for (std::size_t i = 0; i < kf.mapPoints.size(); i++)
		{
			const TPointId pid = kf.mapPoints[i];
			if (pid < 0) continue;
			const auto pit = s.points.find(pid);
			if (pit == s.points.end() || pit->second.bad) continue;
			const float z = kf.features->depth[i];
			if (!(z > 0) || z > maxDepth) continue;  // RGB-D: only close points count (ORB-SLAM2)
			numPoints++;
			const CMapPoint& p = pit->second;
			if (p.observations.size() <= minOtherObservers) continue;
			const int octave = kf.features->keypoints[i].octave;
			std::size_t others = 0;
			for (const auto& [k, kp] : p.observations)
			{
				if (k == id) continue;
				const CKeyFrame& o = *s.keyFrames.at(k);
				if (o.features->keypoints[kp].octave <= octave + 1 && ++others >= minOtherObservers) break;
			}
			if (others >= minOtherObservers) redundant++;
		}
		if (numPoints > 0 && static_cast<double>(redundant) > redundantRatio * static_cast<double>(numPoints))
		{
			s.eraseKeyFrame(kf);
			erased.push_back(id);
		}
	}
	return erased;
}

}  // namespace mrpt_yesslam::sparse_map
