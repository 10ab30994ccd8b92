#include "mrpt_yesslam/loop/CLoopCloser.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <set>

#include "mrpt_yesslam/util/Stopwatch.h"
#include "mrpt_yesslam/optimize/PointFusion.h"
#include "mrpt_yesslam/optimize/PoseGraph.h"

namespace mrpt_yesslam
{
COptionTable CLoopCloser::TOptions::table()
{
	COptionTable t("LoopClosing");
	t.append(detection.table());
	t.integer("essentialWeight", essentialWeight, 0, 100000,
			  "covisibility edges of at least this weight join the essential graph (ORB-SLAM2: 100)");
	t.integer("poseGraphIterations", poseGraphIterations, 1, 10000,
			  "Ceres iterations of the pose graph (ORB-SLAM2: 20)");
	t.flag("globalBundleAdjustment", globalBundleAdjustment,
		   "bundle-adjust every keyframe and point after each loop correction");
	t.integer("globalIterations", globalIterations, 1, 10000, "Ceres iterations of the global BA (ORB-SLAM2: 10)");
	t.real("fuseRadius", fuseRadius, 0.5, 100, "loop fusion search radius, pixels at level 0 (ORB-SLAM2: 4)");
	return t;
}

CLoopCloser::CLoopCloser(const TOptions& opts, CSparseMap& map, double scaleFactor, const TDepthNoise& depthNoise)
	: opts_(opts), map_(map), scaleFactor_(scaleFactor), depthNoise_(depthNoise)
{
}

TLoopCorrection CLoopCloser::correct(const TLoop& loop)
{
	TLoopCorrection c;
	std::map<TKeyFrameId, mrpt::poses::CPose3D> before;
	for (const auto& k : map_.keyFramePoses())
		if (!k.bad) before[k.id] = k.pose;
	if (!before.count(loop.current) || !before.count(loop.matched)) return c;

	// 1. The current keyframe's group, moved rigidly with it.
	std::vector<TKeyFrameId> group = map_.covisible(loop.current, before.size(), 1);
	// The matched keyframe is the fixed side of the loop, even when local mapping connected the two
	// between detection and correction.
	group.erase(std::remove(group.begin(), group.end(), loop.matched), group.end());
	group.insert(group.begin(), loop.current);
	const std::set<TKeyFrameId> groupSet(group.begin(), group.end());
	const mrpt::poses::CPose3D Tcur = before.at(loop.current);
	// From the matched keyframe's pose now (issue 40 c): detection's correctedPose was from its
	// pose then, and a BA since would make the loop edge disagree with the place it closes on.
	const mrpt::poses::CPose3D correctedPose = before.at(loop.matched) + loop.relative;
	std::map<TKeyFrameId, mrpt::poses::CPose3D> corrected;
	std::map<TKeyFrameId, std::set<TKeyFrameId>> linksBefore;
	for (const auto g : group)
	{
		if (!before.count(g)) continue;
		corrected[g] = correctedPose + ((-Tcur) + before.at(g));
		for (const auto& [other, w] : map_.keyFrame(g).connections) linksBefore[g].insert(other);
	}
	c.groupKeyFrames = corrected.size();
	c.correctionMetres =
		std::sqrt(std::pow(correctedPose.x() - Tcur.x(), 2) + std::pow(correctedPose.y() - Tcur.y(), 2) +
				  std::pow(correctedPose.z() - Tcur.z(), 2));
	map_.correctKeyFrames(corrected);

	// 2. Loop fusion: the matched place's points into the corrected group.
	std::vector<TKeyFrameId> place{loop.matched};
	for (const auto n : map_.covisible(loop.matched, 10))
		if (!groupSet.count(n)) place.push_back(n);
	const TLocalMapPoints pts = map_.pointsOfKeyFrames(place);
	std::vector<TFuseCandidate> cands;
	for (const auto& [kp, pid] : loop.pointMatches) cands.push_back({pid, loop.current, kp});
	for (const auto g : group)
	{
		if (g == loop.current || !corrected.count(g)) continue;
		const CKeyFrame kf = map_.keyFrame(g);
		if (kf.bad) continue;
		const auto found = fuseCandidates(kf, corrected.at(g), pts, opts_.fuseRadius, opts_.detection.maxHamming,
										  scaleFactor_, depthNoise_);
		cands.insert(cands.end(), found.begin(), found.end());
	}
	c.fused = map_.fuse(cands);
	map_.addLoopEdge(loop.current, loop.matched);

	// 3. The essential graph. Loop links (new covisibility across the loop, and the loop edge) are
	// measured on the corrected poses, every other edge on the poses before the correction (ORB-SLAM2).
	std::map<TKeyFrameId, mrpt::poses::CPose3D> now;
	for (const auto& k : map_.keyFramePoses())
		if (!k.bad) now[k.id] = k.pose;
	auto old = [&](TKeyFrameId k) { return before.count(k) ? before.at(k) : now.at(k); };
	std::set<std::pair<TKeyFrameId, TKeyFrameId>> links{
		{std::min(loop.current, loop.matched), std::max(loop.current, loop.matched)}};
	for (const auto g : group)
	{
		if (!now.count(g)) continue;
		for (const auto& [other, w] : map_.keyFrame(g).connections)
			if (!groupSet.count(other) && !linksBefore[g].count(other) && now.count(other))
				links.insert({std::min(g, other), std::max(g, other)});
	}
	c.loopLinks = links.size() - 1;
	std::vector<TPoseGraphEdge> edges;
	for (const auto& [a, b] : links)
		if (now.count(a) && now.count(b)) edges.push_back({a, b, (-now.at(a)) + now.at(b), 1.0});
	for (const auto& [a, b] : map_.essentialGraph(opts_.essentialWeight))
		if (!links.count({a, b}) && now.count(a) && now.count(b)) edges.push_back({a, b, (-old(a)) + old(b), 1.0});
	c.graphKeyFrames = now.size();
	c.graphEdges = edges.size();
	const auto t0 = std::chrono::steady_clock::now();
	const auto optimised = optimisePoseGraph(now, edges, {loop.matched}, opts_.poseGraphIterations);
	c.poseGraphMs = msSince(t0);
	map_.applyCorrection(optimised);
	return c;
}

TBundleStats CLoopCloser::globalBundleAdjust(CWriterFirstMutex* writeLock)
{
	const TBundleWindow w = map_.globalBundleWindow();
	if (w.keyFrames.empty() || w.points.empty()) return {};
	if (gbaHook_) gbaHook_();
	TBundleSolveOptions so;
	so.scaleFactor = scaleFactor_;
	so.depthNoise = depthNoise_;
	so.iterations = opts_.globalIterations;
	so.sparse = true;
	// A correction applied meanwhile (a newer loop) makes this result stale: applyGlobalBundle would
	// refuse it, so the solve stops at its next iteration instead of running on (ORB-SLAM2 aborts
	// its global BA when a new loop is detected).
	so.cancelled = [this, &w] { return map_.generation() != w.generation; };
	TBundleSolution sol = solveBundle(w, so);
	if (sol.stats.cancelled) return sol.stats;
	std::unique_lock<CWriterFirstMutex> lk;
	if (writeLock) lk = std::unique_lock<CWriterFirstMutex>(*writeLock);
	sol.stats.applied = map_.applyGlobalBundle(w, sol.poses, sol.positions, sol.outliers);
	return sol.stats;
}
}  // namespace mrpt_yesslam
