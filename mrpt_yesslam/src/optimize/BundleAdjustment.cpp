#include "mrpt_yesslam/optimize/BundleAdjustment.h"

#include <ceres/ceres.h>

#include <array>
#include <cmath>
#include <deque>
#include <memory>

#include "mrpt_yesslam/geometry/CPinholeCamera.h"
#include "mrpt_yesslam/optimize/BundleCosts.h"
#include "mrpt_yesslam/geometry/CPoseOptimizer.h"

namespace mrpt_yesslam
{
TBundleSolution solveBundle(const TBundleWindow& w, const TBundleSolveOptions& o)
{
	TBundleSolution sol;
	TBundleStats& st = sol.stats;
	if (w.keyFrames.empty() || w.points.empty()) return sol;
	st.keyFrames = w.keyFrames.size();
	st.fixedKeyFrames = w.fixedKeyFrames.size();
	st.points = w.points.size();

	// The poses in one block, in keyframe order: Ceres orders a group's parameter blocks by their
	// address, so the solve (to the last bit) depends on where they are, never on the allocator.
	std::vector<std::array<double, 6>> poseStore(w.poses.size());
	std::map<TKeyFrameId, double*> poseParams;
	for (const auto& [k, p] : w.poses)
	{
		double* a = poseStore[poseParams.size()].data();
		poseParams[k] = a;
		cameraPoseToParams(p, a, a + 3);
	}
	std::vector<std::array<double, 3>> X(w.points.size());
	for (std::size_t i = 0; i < X.size(); i++) X[i] = {w.positions[i].x, w.positions[i].y, w.positions[i].z};

	struct Obs
	{
		std::size_t point;
		TKeyFrameId kf;
		bool hasDepth;
	};
	std::vector<Obs> all;
	// all[j]'s cost is costs[j]; declared before the problem, which refers to them to its end.
	std::deque<CRgbdReprojectionCostAnalytic> costs;
	for (std::size_t i = 0; i < w.points.size(); i++)
		for (const auto& [k, kp] : w.observations[i])
		{
			const TFeatures& f = *w.features.at(k);
			const auto& key = f.keypoints[kp];
			const double z = f.depth[kp];
			const bool hasDepth = z > 0;
			const double sigma = std::pow(o.scaleFactor, std::max(0, key.octave));
			const CPinholeCamera K(w.cameras.at(k));
			const bool useDepth = hasDepth && o.depthNoise.measures(z);
			// A coarse keypoint's depth is as uncertain as its position (read where the keypoint is, on slants and near
			// edges), so it takes the pixel's 1/sigma^2 too, as ORB-SLAM2's RGB-D edges do: weighed as a fine one's, it
			// pulled the map towards noisy depths on the real Bonn slice. Tracking keeps the level-0 model.
			const double sigmaZ = useDepth ? o.depthNoise.sigma(z, sigma) : 0.0;
			costs.emplace_back(TRgbdReprojectionCost(key.pt.x, key.pt.y, useDepth ? z : 0.0, sigma, sigmaZ, K.fx(),
													 K.fy(), K.cx(), K.cy()));
			all.push_back({i, k, useDepth});
		}
	st.observations = all.size();
	// The costs in one block and one Huber loss per kind of observation, none owned by Ceres: a
	// cost and a loss allocated per residual were a share of the set-up, repeated for every keyframe.
	// Huber corner at the chi-square 95% threshold, as ORB-SLAM2 (3 DoF: 7.815, 2 DoF: 5.991).
	ceres::HuberLoss lossWithDepth(std::sqrt(7.815)), lossWithoutDepth(std::sqrt(5.991));
	ceres::Problem::Options po;
	po.cost_function_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
	po.loss_function_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
	ceres::Problem problem(po);
	for (std::size_t j = 0; j < all.size(); j++)
	{
		const Obs& ob = all[j];
		double* pp = poseParams.at(ob.kf);
		problem.AddResidualBlock(&costs[j], ob.hasDepth ? &lossWithDepth : &lossWithoutDepth, pp, pp + 3,
								 X[ob.point].data());
	}
	// A point no keyframe of the window measured with depth is constrained only by its rays, and with a short baseline
	// (a still camera) not along them: Ceres moved such points far off, which later made a pose solve collapse. They
	// stay put; ORB-SLAM2's RGB-D edges always carry the right-image coordinate for this reason.
	std::vector<char> hasDepth(w.points.size(), 0);
	for (const auto& o : all)
		if (o.hasDepth) hasDepth[o.point] = 1;
	for (std::size_t i = 0; i < X.size(); i++)
		if (o.depthNoise.used() && !hasDepth[i] && problem.HasParameterBlock(X[i].data()))
			problem.SetParameterBlockConstant(X[i].data());
	std::map<TKeyFrameId, std::size_t> shared;
	for (const auto& obsOfPoint : w.observations)
		if (obsOfPoint.size() >= 2)
			for (const auto& kv : obsOfPoint) shared[kv.first]++;
	std::vector<TKeyFrameId> held = w.fixedKeyFrames;
	for (TKeyFrameId k : w.keyFrames)
		if (shared[k] < o.minSharedObservations && problem.HasParameterBlock(poseParams.at(k)))
		{
			held.push_back(k);
			st.heldKeyFrames++;
		}
	for (TKeyFrameId k : held)
	{
		double* pp = poseParams.at(k);
		if (!problem.HasParameterBlock(pp)) continue;
		problem.SetParameterBlockConstant(pp);
		problem.SetParameterBlockConstant(pp + 3);
	}
	ceres::Solver::Options so;
	// The Schur complement eliminates the points (no two share a residual) and solves for the
	// cameras: said here, instead of Ceres finding that independent set again for every solve
	// (its graph search was a fifth of a local BA's time).
	auto ordering = std::make_shared<ceres::ParameterBlockOrdering>();
	for (auto& x : X)
		if (problem.HasParameterBlock(x.data())) ordering->AddElementToGroup(x.data(), 0);
	for (auto& [k, pp] : poseParams)
		if (problem.HasParameterBlock(pp))
		{
			ordering->AddElementToGroup(pp, 1);
			ordering->AddElementToGroup(pp + 3, 1);
		}
	so.linear_solver_ordering = ordering;
	// A local window has at most a few dozen cameras: Ceres' dense Schur complement beats the sparse one there.
	so.linear_solver_type = o.sparse ? ceres::SPARSE_SCHUR : ceres::DENSE_SCHUR;
	so.max_num_iterations = o.iterations;
	so.num_threads = o.threads;
	so.logging_type = ceres::SILENT;
	struct CCancel : ceres::IterationCallback
	{
		const std::function<bool()>& cancelled;
		explicit CCancel(const std::function<bool()>& c) : cancelled(c) {}
		ceres::CallbackReturnType operator()(const ceres::IterationSummary&) override
		{
			return cancelled() ? ceres::SOLVER_ABORT : ceres::SOLVER_CONTINUE;
		}
	} cancel(o.cancelled);
	if (o.cancelled) so.callbacks.push_back(&cancel);
	ceres::Solver::Summary sum;
	ceres::Solve(so, &problem, &sum);
	st.initialCost = sum.initial_cost;
	st.finalCost = sum.final_cost;
	st.iterations = static_cast<int>(sum.iterations.size());
	if (sum.termination_type == ceres::USER_FAILURE)
	{
		st.cancelled = true;
		return sol;  // stale: nothing to write back
	}

	// Observations that are still outliers after the solve are removed from the map (ORB-SLAM2).
	std::vector<std::pair<TPointId, TKeyFrameId>> outliers;
	for (std::size_t j = 0; j < all.size(); j++)
	{
		const Obs& o = all[j];
		const double* pp = poseParams.at(o.kf);
		double r[3];
		costs[j].cost()(pp, pp + 3, X[o.point].data(), r);
		const double chi2 = r[0] * r[0] + r[1] * r[1] + r[2] * r[2];
		if (chi2 > (o.hasDepth ? 7.815 : 5.991)) outliers.emplace_back(w.points[o.point], o.kf);
	}
	st.outliers = outliers.size();
	sol.outliers = std::move(outliers);
	for (TKeyFrameId k : w.keyFrames)
	{
		const double* pp = poseParams.at(k);
		sol.poses[k] = cameraPoseFromParams(pp, pp + 3);
	}
	for (const auto& x : X) sol.positions.push_back({x[0], x[1], x[2]});
	return sol;
}
}  // namespace mrpt_yesslam
