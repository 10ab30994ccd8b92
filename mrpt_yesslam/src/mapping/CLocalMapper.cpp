#include "mrpt_yesslam/mapping/CLocalMapper.h"

#include <ceres/ceres.h>
#include <mrpt/config/CConfigFileBase.h>

#include <algorithm>
#include <array>
#include <cmath>

#include "mrpt_yesslam/geometry/CPinholeCamera.h"
#include "mrpt_yesslam/optimize/BundleCosts.h"
#include "mrpt_yesslam/optimize/PointFusion.h"
#include "mrpt_yesslam/geometry/CPoseOptimizer.h"

namespace mrpt_yesslam
{
COptionTable CLocalMapper::TOptions::table()
{
	COptionTable t("LocalMapping");
	t.flag("bundleAdjustment", bundleAdjustment, "local bundle adjustment after each keyframe");
	t.count("covisibleKeyFrames", covisibleKeyFrames, 0, 1000, "keyframes optimised besides the new one");
	t.count("maxFixedKeyFrames", maxFixedKeyFrames, 0, 1000, "other keyframes seeing the points, held fixed");
	t.integer("iterations", iterations, 1, 1000, "Ceres iterations");
	t.real("cullFoundRatio", cullFoundRatio, 0, 1,
		   "young points found in fewer than this share of the frames that should see them are culled");
	t.count("cullMinObservations", cullMinObservations, 0, 1000, "young points seen by fewer keyframes are culled");
	t.count("fuseKeyFrames", fuseKeyFrames, 0, 1000,
			"neighbours searched for duplicate points (ORB-SLAM2 RGB-D: 10); 0 = no fusion (it cost accuracy, "
			"docs/benchmarks.md)");
	t.real("fuseRadius", fuseRadius, 0.5, 100, "fusion search radius, pixels at level 0 (x scale^octave)");
	t.integer("fuseMaxHamming", fuseMaxHamming, 0, 256, "fusion: largest descriptor distance (ORB-SLAM2's TH_LOW)");
	t.flag("keyFrameCulling", keyFrameCulling, "erase redundant keyframes (ORB-SLAM2's KeyFrameCulling)");
	t.real("redundantRatio", redundantRatio, 0, 1, "a keyframe goes when more than this share of its close points ...");
	t.count("redundantObservers", redundantObservers, 1, 1000,
			"... is seen by at least this many other keyframes at the same or finer scale");
	return t;
}

CLocalMapper::CLocalMapper(const TOptions& opts, CSparseMap& map, double scaleFactor, double maxDepth,
						   const TDepthNoise& depthNoise)
	: opts_(opts), map_(map), scaleFactor_(scaleFactor), maxDepth_(maxDepth), noise_(depthNoise)
{
}

TMappingStats CLocalMapper::step(TKeyFrameId kf)
{
	TMappingStats st;
	st.culledPoints = map_.cullRecentPoints(kf, opts_.cullFoundRatio, opts_.cullMinObservations);
	if (opts_.fuseKeyFrames > 0) st.fused = fuseWithNeighbours(kf);
	if (opts_.bundleAdjustment) st.bundle = bundleAdjust(kf);
	if (opts_.keyFrameCulling)
		st.erasedKeyFrames = map_.cullRedundantKeyFrames(kf, opts_.redundantRatio, opts_.redundantObservers, maxDepth_);
	return st;
}

std::size_t CLocalMapper::fuseWithNeighbours(TKeyFrameId kfId)
{
	const std::vector<TKeyFrameId> neighbours = map_.covisible(kfId, opts_.fuseKeyFrames, 1);
	if (neighbours.empty()) return 0;
	std::vector<TFuseCandidate> cands;
	auto search = [&](const TLocalMapPoints& pts, const CKeyFrame& into)
	{
		const auto c =
			fuseCandidates(into, into.pose, pts, opts_.fuseRadius, opts_.fuseMaxHamming, scaleFactor_, noise_);
		cands.insert(cands.end(), c.begin(), c.end());
	};
	const CKeyFrame cur = map_.keyFrame(kfId);
	const TLocalMapPoints curPts = map_.keyFramePoints(kfId);
	std::vector<TPointId> neighbourIds;
	for (TKeyFrameId n : neighbours)
	{
		const CKeyFrame nk = map_.keyFrame(n);
		search(curPts, nk);  // the new keyframe's points into each neighbour
		for (TPointId p : nk.mapPoints)
			if (p >= 0) neighbourIds.push_back(p);
	}
	std::sort(neighbourIds.begin(), neighbourIds.end());
	neighbourIds.erase(std::unique(neighbourIds.begin(), neighbourIds.end()), neighbourIds.end());
	search(map_.pointsById(neighbourIds), cur);  // the neighbours' points into the new keyframe
	return map_.fuse(cands);
}

TBundleStats CLocalMapper::bundleAdjust(TKeyFrameId kf)
{
	const TBundleWindow w = map_.bundleWindow(kf, opts_.covisibleKeyFrames, opts_.maxFixedKeyFrames);
	if (w.keyFrames.empty() || w.points.empty()) return {};
	TBundleSolveOptions so;
	so.scaleFactor = scaleFactor_;
	so.depthNoise = noise_;
	so.iterations = opts_.iterations;
	TBundleSolution sol = solveBundle(w, so);
	sol.stats.applied = map_.applyBundle(w, sol.poses, sol.positions, sol.outliers);
	return sol.stats;
}
}  // namespace mrpt_yesslam
