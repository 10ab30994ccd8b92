#include "mrpt_yesslam/mapping/CLocalMapper.h"

#include <ceres/ceres.h>
#include <mrpt/config/CConfigFileBase.h>

#include <algorithm>
#include <array>
#include <cmath>

#include "mrpt_yesslam/feature/COrbMatcher.h"
#include "mrpt_yesslam/geometry/CPinholeCamera.h"
#include "mrpt_yesslam/mapping/BundleCosts.h"
#include "mrpt_yesslam/tracking/CPoseOptimizer.h"

namespace mrpt_yesslam
{
COptionTable CLocalMapper::TOptions::table()
{
	COptionTable t("LocalMapping");
	t.flag("bundleAdjustment", bundleAdjustment, "local bundle adjustment after each keyframe");
	t.count("covisibleKeyFrames", covisibleKeyFrames, 0, 1000, "keyframes optimised besides the new one");
	t.count("maxFixedKeyFrames", maxFixedKeyFrames, 0, 1000, "other keyframes seeing the points, held fixed");
	t.integer("iterations", iterations, 1, 1000, "Ceres iterations");
	t.real("depthNoise", depthNoise, 0, 1, "depth residual sigma_z = depthNoise x z^2 (m); 0 = reprojection only");
	t.real("cullFoundRatio", cullFoundRatio, 0, 1, "young points found in fewer than this share of the frames that should see them are culled");
	t.count("cullMinObservations", cullMinObservations, 0, 1000, "young points seen by fewer keyframes are culled");
	t.count("fuseKeyFrames", fuseKeyFrames, 0, 1000, "neighbours searched for duplicate points (ORB-SLAM2 RGB-D: 10); 0 = no fusion (it cost accuracy, README)");
	t.real("fuseRadius", fuseRadius, 0.5, 100, "fusion search radius, pixels at level 0 (x scale^octave)");
	t.integer("fuseMaxHamming", fuseMaxHamming, 0, 256, "fusion: largest descriptor distance (ORB-SLAM2's TH_LOW)");
	t.flag("keyFrameCulling", keyFrameCulling, "erase redundant keyframes (ORB-SLAM2's KeyFrameCulling)");
	t.real("redundantRatio", redundantRatio, 0, 1, "a keyframe goes when more than this share of its close points ...");
	t.count("redundantObservers", redundantObservers, 1, 1000, "... is seen by at least this many other keyframes at the same or finer scale");
	return t;
}

CLocalMapper::CLocalMapper(const TOptions& opts, CSparseMap& map, double scaleFactor, double maxDepth)
	: opts_(opts), map_(map), scaleFactor_(scaleFactor), maxDepth_(maxDepth)
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

namespace
{
// A keyframe's measurements as the matcher takes them.
TFrame asFrame(const CKeyFrame& kf)
{
	TFrame f;
	f.id = kf.frameId;
	f.camera = kf.camera;
	f.features = *kf.features;
	f.mapPoints = kf.mapPoints;
	return f;
}
}  // namespace

std::size_t CLocalMapper::fuseWithNeighbours(TKeyFrameId kfId)
{
	const std::vector<TKeyFrameId> neighbours = map_.covisible(kfId, opts_.fuseKeyFrames, 1);
	if (neighbours.empty()) return 0;
	// Projection search as tracking's, with ORB-SLAM2's Fuse thresholds: a small window and TH_LOW,
	// no ratio test (the best match within the window is taken).
	const COrbMatcher matcher(opts_.fuseMaxHamming, 1.0);
	std::vector<TFuseCandidate> cands;
	auto search = [&](const TLocalMapPoints& pts, const CKeyFrame& into)
	{
		if (pts.ids.empty() || !into.features) return;
		const TFrame f = asFrame(into);
		const mrpt::poses::CPose3D Tcw = -into.pose;
		for (const TMatch& m : matcher.searchByProjection(f, into.pose, pts, opts_.fuseRadius, nullptr, false, scaleFactor_))
		{
			// RGB-D: the keypoint's own depth must agree with the point's (3 sigma of the Kinect model
			// plus 2 cm), as ORB-SLAM2 checks the right-image coordinate.
			const float d = f.features.depth[m.keypoint];
			if (d > 0)
			{
				const auto& P = pts.positions[m.point];
				double x, y, z;
				Tcw.composePoint(P.x, P.y, P.z, x, y, z);
				if (std::abs(d - z) > 0.02 + 3 * opts_.depthNoise * z * z) continue;
			}
			cands.push_back({pts.ids[m.point], into.id, m.keypoint});
		}
	};
	const CKeyFrame cur = map_.keyFrame(kfId);
	const TLocalMapPoints curPts = map_.keyFramePoints(kfId);
	std::vector<TPointId> neighbourIds;
	for (TKeyFrameId n : neighbours)
	{
		const CKeyFrame nk = map_.keyFrame(n);
		search(curPts, nk);	 // the new keyframe's points into each neighbour
		for (TPointId p : nk.mapPoints)
			if (p >= 0) neighbourIds.push_back(p);
	}
	std::sort(neighbourIds.begin(), neighbourIds.end());
	neighbourIds.erase(std::unique(neighbourIds.begin(), neighbourIds.end()), neighbourIds.end());
	search(map_.pointsById(neighbourIds), cur);	 // the neighbours' points into the new keyframe
	return map_.fuse(cands);
}

TBundleStats CLocalMapper::bundleAdjust(TKeyFrameId kf)
{
	TBundleStats st;
	const TBundleWindow w = map_.bundleWindow(kf, opts_.covisibleKeyFrames, opts_.maxFixedKeyFrames);
	if (w.keyFrames.empty() || w.points.empty()) return st;
	st.keyFrames = w.keyFrames.size();
	st.fixedKeyFrames = w.fixedKeyFrames.size();
	st.points = w.points.size();

	std::map<TKeyFrameId, std::array<double, 6>> poseParams;
	for (const auto& [k, p] : w.poses)
	{
		auto& a = poseParams[k];
		cameraPoseToParams(p, a.data(), a.data() + 3);
	}
	std::vector<std::array<double, 3>> X(w.points.size());
	for (std::size_t i = 0; i < X.size(); i++) X[i] = {w.positions[i].x, w.positions[i].y, w.positions[i].z};

	struct Obs
	{
		std::size_t point;
		TKeyFrameId kf;
		TRgbdReprojectionCost cost;
		bool hasDepth;
	};
	std::vector<Obs> all;
	ceres::Problem problem;
	for (std::size_t i = 0; i < w.points.size(); i++)
		for (const auto& [k, kp] : w.observations[i])
		{
			const TFeatures& f = *w.features.at(k);
			const auto& key = f.keypoints[kp];
			const double z = f.depth[kp];
			const bool hasDepth = z > 0;
			const double sigma = std::pow(scaleFactor_, std::max(0, key.octave));
			const CPinholeCamera K(w.cameras.at(k));
			const bool useDepth = hasDepth && opts_.depthNoise > 0;
			TRgbdReprojectionCost c(
				key.pt.x, key.pt.y, useDepth ? z : 0.0, sigma, useDepth ? opts_.depthNoise * z * z : 0.0, K.fx(), K.fy(), K.cx(), K.cy());
			all.push_back({i, k, c, useDepth});
			auto* cost = new ceres::AutoDiffCostFunction<TRgbdReprojectionCost, 3, 3, 3, 3>(new TRgbdReprojectionCost(c));
			// Huber corner at the chi-square 95% threshold, as ORB-SLAM2 (3 DoF: 7.815, 2 DoF: 5.991).
			auto* loss = new ceres::HuberLoss(std::sqrt(useDepth ? 7.815 : 5.991));
			auto& pp = poseParams.at(k);
			problem.AddResidualBlock(cost, loss, pp.data(), pp.data() + 3, X[i].data());
		}
	st.observations = all.size();
	// A point that no keyframe of the window measured with depth is constrained only by its rays,
	// and with a short baseline (a still camera: walking_static) not at all along them: Ceres then
	// moves it anywhere (measured: points 100+ m away, which later made a pose solve collapse and
	// relocalisation jump by metres). Such points keep their position; ORB-SLAM2's stereo/RGB-D
	// edges always carry the right-image coordinate for the same reason.
	std::vector<char> hasDepth(w.points.size(), 0);
	for (const auto& o : all)
		if (o.hasDepth) hasDepth[o.point] = 1;
	for (std::size_t i = 0; i < X.size(); i++)
		if (opts_.depthNoise > 0 && !hasDepth[i] && problem.HasParameterBlock(X[i].data()))
			problem.SetParameterBlockConstant(X[i].data());
	for (TKeyFrameId k : w.fixedKeyFrames)
	{
		auto& pp = poseParams.at(k);
		problem.SetParameterBlockConstant(pp.data());
		problem.SetParameterBlockConstant(pp.data() + 3);
	}
	ceres::Solver::Options so;
	// A local window has at most a few dozen cameras: Ceres' dense Schur complement beats the sparse
	// one there (measured: local BA 118 -> ~100 ms median per keyframe on walking_halfsphere).
	so.linear_solver_type = ceres::DENSE_SCHUR;
	so.max_num_iterations = opts_.iterations;
	so.num_threads = 1;
	so.logging_type = ceres::SILENT;
	ceres::Solver::Summary sum;
	ceres::Solve(so, &problem, &sum);
	st.initialCost = sum.initial_cost;
	st.finalCost = sum.final_cost;

	// Observations that are still outliers after the solve are removed from the map (ORB-SLAM2).
	std::vector<std::pair<TPointId, TKeyFrameId>> outliers;
	for (const auto& o : all)
	{
		const auto& pp = poseParams.at(o.kf);
		double r[3];
		o.cost(pp.data(), pp.data() + 3, X[o.point].data(), r);
		const double chi2 = r[0] * r[0] + r[1] * r[1] + r[2] * r[2];
		if (chi2 > (o.hasDepth ? 7.815 : 5.991)) outliers.emplace_back(w.points[o.point], o.kf);
	}
	st.outliers = outliers.size();
	std::map<TKeyFrameId, mrpt::poses::CPose3D> poses;
	for (TKeyFrameId k : w.keyFrames)
	{
		const auto& pp = poseParams.at(k);
		poses[k] = cameraPoseFromParams(pp.data(), pp.data() + 3);
	}
	std::vector<mrpt::math::TPoint3D> positions;
	for (const auto& x : X) positions.push_back({x[0], x[1], x[2]});
	st.applied = map_.applyBundle(w, poses, positions, outliers);
	return st;
}
}  // namespace mrpt_yesslam
