#include "MapWindows.h"

#include <algorithm>
#include <set>
#include <unordered_set>

#include "MapCorrection.h"

namespace mrpt_yesslam::sparse_map
{
std::vector<TKeyFrameId> localKeyFrames(const TSparseMapStore& s, const std::vector<TPointId>& seeds,
										TKeyFrameId fallback, std::size_t maxKeyFrames, std::size_t neighbours)
{
	std::unordered_map<TKeyFrameId, int> shared;
	for (TPointId pid : seeds)
		if (const CMapPoint* p = s.goodPoint(pid))
			for (const auto& [k, kp] : p->observations)
				if (!s.keyFrames.at(k)->bad) shared[k]++;
	// Most shared first; ties to the newer keyframe (closer in time to the frame).
	std::vector<std::pair<int, TKeyFrameId>> order;
	for (const auto& [k, n] : shared) order.emplace_back(n, k);
	std::sort(order.begin(), order.end(),
			  [](const auto& a, const auto& b)
			  { return a.first != b.first ? a.first > b.first : a.second > b.second; });
	std::vector<TKeyFrameId> out;
	std::unordered_set<TKeyFrameId> in;
	const auto add = [&](TKeyFrameId k)
	{
		if (out.size() >= maxKeyFrames || in.count(k)) return;
		const auto it = s.keyFrames.find(k);
		if (it == s.keyFrames.end() || it->second->bad) return;
		in.insert(k);
		out.push_back(k);
	};
	for (const auto& [n, k] : order) add(k);
	if (out.empty())
		if (s.keyFrames.count(fallback)) add(s.goodAncestor(fallback));
	// K2: around the keyframes that share points with the frame (ORB-SLAM2 takes 10 covisible,
	// one child and the parent of each; all children here, the tree is shallow in our maps).
	const std::size_t k1 = out.size();
	for (std::size_t i = 0; i < k1 && out.size() < maxKeyFrames; i++)
	{
		const CKeyFrame& kf = *s.keyFrames.at(out[i]);
		for (TKeyFrameId n : s.covisible(kf.id, neighbours, 1)) add(n);
		for (TKeyFrameId c : kf.children) add(c);
		if (kf.parent) add(*kf.parent);
	}
	return out;
}

TBundleWindow bundleWindow(const TSparseMapStore& s, TKeyFrameId id, std::size_t numCovisible, std::size_t maxFixed)
{
	TBundleWindow w;
	w.generation = s.generation;
	const auto cit = s.keyFrames.find(id);
	if (cit == s.keyFrames.end() || cit->second->bad) return w;
	w.keyFrames = s.covisible(id, numCovisible, 1);
	w.keyFrames.insert(w.keyFrames.begin(), id);
	const std::set<TKeyFrameId> local(w.keyFrames.begin(), w.keyFrames.end());
	std::set<TPointId> pts;
	for (TKeyFrameId k : w.keyFrames)
		for (TPointId pid : s.keyFrames.at(k)->mapPoints)
			if (pid >= 0)
				if (auto it = s.points.find(pid); it != s.points.end() && !it->second.bad) pts.insert(pid);
	std::map<TKeyFrameId, int> fixedCount;
	for (TPointId pid : pts)
		for (const auto& [k, kp] : s.points.at(pid).observations)
			if (!local.count(k)) fixedCount[k]++;
	std::vector<std::pair<int, TKeyFrameId>> order;
	for (const auto& [k, n] : fixedCount) order.emplace_back(-n, k);
	std::sort(order.begin(), order.end());
	for (std::size_t i = 0; i < order.size() && w.fixedKeyFrames.size() < maxFixed; i++)
		w.fixedKeyFrames.push_back(order[i].second);
	// The first keyframe anchors the gauge (ORB-SLAM2 fixes the origin keyframe).
	const TKeyFrameId root = s.keyFrames.begin()->first;
	if (local.count(root))
	{
		w.keyFrames.erase(std::find(w.keyFrames.begin(), w.keyFrames.end(), root));
		w.fixedKeyFrames.push_back(root);
	}
	std::set<TKeyFrameId> all(w.keyFrames.begin(), w.keyFrames.end());
	all.insert(w.fixedKeyFrames.begin(), w.fixedKeyFrames.end());
	for (TKeyFrameId k : all)
	{
		const CKeyFrame& kf = *s.keyFrames.at(k);
		w.poses[k] = kf.pose;
		w.features[k] = kf.features;
		w.cameras[k] = kf.camera;
	}
	for (TPointId pid : pts)
	{
		const auto& p = s.points.at(pid);
		std::map<TKeyFrameId, std::size_t> obs;
		for (const auto& [k, kp] : p.observations)
			if (all.count(k)) obs[k] = kp;
		w.points.push_back(pid);
		w.positions.push_back(p.position);
		w.observations.push_back(std::move(obs));
	}
	return w;
}

TBundleWindow globalBundleWindow(const TSparseMapStore& s)
{
	TBundleWindow w;
	w.generation = s.generation;
	for (const auto& [id, kf] : s.keyFrames)
	{
		if (kf->bad) continue;
		(id == s.keyFrames.begin()->first ? w.fixedKeyFrames : w.keyFrames).push_back(id);
		w.poses[id] = kf->pose;
		w.features[id] = kf->features;
		w.cameras[id] = kf->camera;
	}
	for (const auto& [pid, p] : s.points)
	{
		if (p.bad) continue;
		std::map<TKeyFrameId, std::size_t> obs;
		for (const auto& [k, kp] : p.observations)
			if (w.poses.count(k)) obs[k] = kp;
		if (obs.empty()) continue;
		w.points.push_back(pid);
		w.positions.push_back(p.position);
		w.observations.push_back(std::move(obs));
	}
	return w;
}

bool applyBundle(TSparseMapStore& s, const TBundleWindow& w, const std::map<TKeyFrameId, mrpt::poses::CPose3D>& poses,
				 const std::vector<mrpt::math::TPoint3D>& positions,
				 const std::vector<std::pair<TPointId, TKeyFrameId>>& outliers)
{
	if (w.generation != s.generation) return false;
	for (const auto& [k, p] : poses)
		if (auto it = s.keyFrames.find(k); it != s.keyFrames.end() && !it->second->bad) it->second->pose = p;
	for (std::size_t i = 0; i < w.points.size() && i < positions.size(); i++)
		if (auto it = s.points.find(w.points[i]); it != s.points.end() && !it->second.bad)
			it->second.position = positions[i];
	s.eraseOutliers(outliers);
	return true;
}

bool applyGlobalBundle(TSparseMapStore& s, const TBundleWindow& w,
					   const std::map<TKeyFrameId, mrpt::poses::CPose3D>& poses,
					   const std::vector<mrpt::math::TPoint3D>& positions,
					   const std::vector<std::pair<TPointId, TKeyFrameId>>& outliers)
{
	if (w.generation != s.generation) return false;
	// Keyframes and points made since the copy follow their ancestors' correction (ORB-SLAM2's
	// RunGlobalBundleAdjustment), the window's points take their optimised positions.
	const std::set<TPointId> optimised(w.points.begin(), w.points.end());
	correct(s, poses, true, optimised);
	for (std::size_t i = 0; i < w.points.size() && i < positions.size(); i++)
		if (auto it = s.points.find(w.points[i]); it != s.points.end() && !it->second.bad)
			it->second.position = positions[i];
	s.eraseOutliers(outliers);
	return true;
}

}  // namespace mrpt_yesslam::sparse_map
