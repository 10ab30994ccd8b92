#include "mrpt_yesslam/dynamic/CGeometricDynamicCheck.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>

namespace mrpt_yesslam
{
namespace
{
// Two depths belong to different surfaces (a person in front of the wall): the one rule for the
// mover check's groups and for the regions it hands to the next frames.
bool depthGap(double a, double b)
{
	return std::abs(a - b) > std::max(0.15, 0.1 * std::min(a, b));
}
}  // namespace

COptionTable CGeometricDynamicCheck::TOptions::table()
{
	COptionTable t("GeometricCheck");
	t.flag("enabled", enabled,
		   "the geometric check beside the mask: uncertain keypoints (where a mover was found; with boxes, inside a "
		   "dynamic box) join the pose only if they agree with the pose from the others, and the mover check (false: "
		   "every unmasked keypoint is trusted, as the paper)");
	t.text("boxes", boxes,
		   "keypoints inside a dynamic detection box (grown by boxMargin) but outside its mask are uncertain: they "
		   "join a pose only where the certain ones' pose agrees, and never start a map point (false: the mask and the "
		   "mover check judge them); auto: true for localisation in a loaded map (--localize-only: the map cannot cull "
		   "what people left in it), false when mapping",
		   {"auto", "true", "false"});
	t.real("boxMargin", boxMargin, 0, 1, "a dynamic box grows by this share of its size on every side");
	t.count("minCertainInliers", minCertainInliers, 4, 100000,
			"fewer inliers outside every dynamic box: the check stands aside for the frame");
	t.count(
		"minBlindedCertain", minBlindedCertain, 0, 100000,
		"a frame with too few certain matches and more uncertain ones gets a pose from at least this many certain ones "
		"when the uncertain ones agreeing with it bring minCertainInliers inliers; else it is lost (0: always lost)");
	t.flag("movers", movers,
		   "box-free check for movers no detector reports: a depth-coherent group of matches that the pose from the "
		   "others cannot explain leaves the solve");
	t.real("moverCell", moverCell, 4, 10000, "image cell side of the mover check's groups, pixels");
	t.real("moverChi2", moverChi2, 1, 1e6,
		   "a group misses when n |mean whitened residual|^2 under the pose from the others exceeds this; the worst "
		   "such group ...");
	t.real("moverShift", moverShift, 0, 100,
		   "... moves (leaves the solve) when its mean displacement under that pose is at least this, m (else the "
		   "others are tested again without it)");
	return t;
}

void CGeometricDynamicCheck::classify(TFeatures& f, const std::vector<TDetection>& detections,
									  const cv::Size& image) const
{
	f.uncertain.assign(f.keypoints.size(), false);
	if (!opts_.enabled || !opts_.boxesOn()) return;
	std::vector<cv::Rect2f> boxes;
	for (const auto& d : detections)
		if (d.dynamic)
		{
			const float mx = static_cast<float>(opts_.boxMargin) * d.box.width,
						my = static_cast<float>(opts_.boxMargin) * d.box.height;
			boxes.push_back(cv::Rect2f(d.box.x - mx, d.box.y - my, d.box.width + 2 * mx, d.box.height + 2 * my) &
							cv::Rect2f(0, 0, static_cast<float>(image.width), static_cast<float>(image.height)));
		}
	if (boxes.empty()) return;
	for (std::size_t i = 0; i < f.keypoints.size(); i++)
	{
		if (f.dynamic[i]) continue;
		for (const auto& b : boxes)
			if (b.contains(f.keypoints[i].pt))
			{
				f.uncertain[i] = true;
				break;
			}
	}
}

std::vector<CGeometricDynamicCheck::TMoverRegion> CGeometricDynamicCheck::moverRegions(
	const TFeatures& f, const std::vector<std::size_t>& moving) const
{
	std::vector<std::size_t> v;
	for (std::size_t i : moving)
		if (i < f.depth.size() && f.depth[i] > 0) v.push_back(i);
	std::sort(v.begin(), v.end(), [&](std::size_t a, std::size_t b) { return f.depth[a] < f.depth[b]; });
	std::vector<TMoverRegion> out;
	std::vector<cv::Vec4f> ext;  // x0, y0, x1, y1 of each region
	for (std::size_t k = 0; k < v.size(); k++)
	{
		const float z = f.depth[v[k]];
		const cv::Point2f& p = f.keypoints[v[k]].pt;
		if (k == 0 || depthGap(f.depth[v[k - 1]], z))
		{
			out.emplace_back();
			out.back().zMin = z;
			ext.emplace_back(p.x, p.y, p.x, p.y);
		}
		auto& e = ext.back();
		e = cv::Vec4f(std::min(e[0], p.x), std::min(e[1], p.y), std::max(e[2], p.x), std::max(e[3], p.y));
		out.back().zMax = z;
	}
	for (std::size_t k = 0; k < out.size(); k++)
		out[k].box = cv::Rect2f(ext[k][0], ext[k][1], ext[k][2] - ext[k][0], ext[k][3] - ext[k][1]);
	return out;
}

void CGeometricDynamicCheck::markMovers(TFeatures& f, const std::vector<TMoverRegion>& regions) const
{
	if (!opts_.enabled || !opts_.movers || regions.empty()) return;
	if (f.uncertain.size() != f.keypoints.size()) f.uncertain.assign(f.keypoints.size(), false);
	constexpr float kDepthMargin = 0.3f;
	for (const auto& r : regions)
	{
		const float mx = static_cast<float>(opts_.boxMargin) * r.box.width + 8,
					my = static_cast<float>(opts_.boxMargin) * r.box.height + 8;
		const cv::Rect2f b(r.box.x - mx, r.box.y - my, r.box.width + 2 * mx, r.box.height + 2 * my);
		for (std::size_t i = 0; i < f.keypoints.size(); i++)
		{
			if (f.dynamic[i] || !b.contains(f.keypoints[i].pt)) continue;
			const float z = i < f.depth.size() ? f.depth[i] : 0.f;
			if (z > 0 && z >= r.zMin - kDepthMargin && z <= r.zMax + kDepthMargin) f.uncertain[i] = true;
		}
	}
}

TPoseEstimate CGeometricDynamicCheck::refine(const CPoseOptimizer& optimizer, const std::vector<TPoseObservation>& obs,
											 const std::vector<bool>& uncertain, const mrpt::img::TCamera& K,
											 const mrpt::poses::CPose3D& guess, TStats* stats) const
{
	TStats st;
	std::vector<std::size_t> certainIdx, uncertainIdx;
	for (std::size_t i = 0; i < obs.size(); i++)
		(i < uncertain.size() && uncertain[i] ? uncertainIdx : certainIdx).push_back(i);
	st.certain = certainIdx.size();
	st.uncertain = uncertainIdx.size();
	const auto plain = [&]
	{
		// A certain-first attempt that failed leaves nothing behind: the movers it found were
		// judged among its own matches, and counting them again here tightened the guard that
		// lets a mover leave (and counted it twice in the stats).
		TStats fresh;
		fresh.certain = st.certain;
		fresh.uncertain = st.uncertain;
		st = fresh;
		const TPoseEstimate e = rejectMovingClusters(optimizer, obs, K, optimizer.refine(obs, K, guess), st);
		if (stats) *stats = st;
		return e;
	};
	if (!opts_.enabled || uncertainIdx.empty()) return plain();
	if (certainIdx.size() < opts_.minCertainInliers)
	{
		// Blinded: a dynamic object fills most of the view, and a pose from everything would follow it far off: there
		// is none unless the few certain matches give one that enough uncertain ones (background beside the person, in
		// its box) confirm; else the frame is lost. With few features of either kind the check stands aside.
		if (uncertainIdx.size() >= certainIdx.size())
		{
			if (opts_.minBlindedCertain > 0 && certainIdx.size() >= opts_.minBlindedCertain)
			{
				TPoseEstimate e = certainFirst(optimizer, obs, certainIdx, uncertainIdx, K, guess,
											   opts_.minBlindedCertain, opts_.minCertainInliers, st);
				if (e.ok)
				{
					if (stats) *stats = st;
					return e;
				}
			}
			st.blinded = true;
			if (stats) *stats = st;
			TPoseEstimate none;
			none.inlier.assign(obs.size(), false);
			none.cameraInWorld = guess;
			return none;
		}
		return plain();
	}
	TPoseEstimate e = certainFirst(optimizer, obs, certainIdx, uncertainIdx, K, guess, opts_.minCertainInliers, 0, st);
	if (!e.ok) return plain();
	if (stats) *stats = st;
	return e;
}

TPoseEstimate CGeometricDynamicCheck::certainFirst(const CPoseOptimizer& optimizer,
												   const std::vector<TPoseObservation>& obs,
												   const std::vector<std::size_t>& certainIdx,
												   const std::vector<std::size_t>& uncertainIdx,
												   const mrpt::img::TCamera& K, const mrpt::poses::CPose3D& guess,
												   std::size_t minFirst, std::size_t minTotal, TStats& st) const
{
	TPoseEstimate failed;
	failed.inlier.assign(obs.size(), false);
	failed.cameraInWorld = guess;
	std::vector<TPoseObservation> certain;
	certain.reserve(certainIdx.size());
	for (std::size_t i : certainIdx) certain.push_back(obs[i]);
	const TPoseEstimate first = rejectMovingClusters(optimizer, certain, K, optimizer.refine(certain, K, guess), st);
	if (!first.ok || first.numInliers < minFirst) return failed;

	std::vector<TPoseObservation> unsure;
	for (std::size_t i : uncertainIdx) unsure.push_back(obs[i]);
	const std::vector<bool> agree = optimizer.consistent(unsure, K, first.cameraInWorld);
	// Matches of a moving group stay out, whatever the uncertain ones say.
	std::vector<std::size_t> used;
	for (std::size_t k = 0; k < certainIdx.size(); k++)
		if (!first.isMoving(k)) used.push_back(certainIdx[k]);
	const std::size_t certainUsed = used.size();
	for (std::size_t j = 0; j < uncertainIdx.size(); j++)
		if (agree[j]) used.push_back(uncertainIdx[j]);
	if (first.numInliers + (used.size() - certainUsed) < minTotal) return failed;
	st.applied = true;
	st.uncertainAccepted = used.size() - certainUsed;

	TPoseEstimate out;
	if (st.uncertainAccepted == 0)
		out = first;
	else
	{
		std::vector<TPoseObservation> all;
		all.reserve(used.size());
		for (std::size_t i : used) all.push_back(obs[i]);
		out = optimizer.refine(all, K, first.cameraInWorld);
	}
	// Back to the caller's indices.
	const std::vector<std::size_t>& from = st.uncertainAccepted == 0 ? certainIdx : used;
	const TPoseEstimate sub = out;
	out.inlier.assign(obs.size(), false);
	for (std::size_t k = 0; k < from.size(); k++) out.inlier[from[k]] = sub.inlier[k];
	out.moving.assign(obs.size(), false);
	for (std::size_t k = 0; k < certainIdx.size(); k++) out.moving[certainIdx[k]] = first.isMoving(k);
	return out;
}

namespace
{
// Union-find over the mover check's nodes.
std::size_t findRoot(std::vector<std::size_t>& parent, std::size_t i)
{
	while (parent[i] != i) i = parent[i] = parent[parent[i]];
	return i;
}
}  // namespace

std::vector<std::vector<std::size_t>> CGeometricDynamicCheck::depthCoherentGroups(
	const std::vector<TPoseObservation>& obs, const std::vector<bool>& use, const mrpt::img::TCamera& K) const
{
	const double side = opts_.moverCell;
	const int cols = std::max(1, static_cast<int>(std::ceil(K.ncols / side)));
	const int rows = std::max(1, static_cast<int>(std::ceil(K.nrows / side)));
	// Nodes: each cell's RGB-D matches split where their sorted depths jump.
	std::vector<std::vector<std::size_t>> byCell(static_cast<std::size_t>(cols * rows));
	for (std::size_t i = 0; i < obs.size(); i++)
	{
		if (!use[i] || !(obs[i].depth > 0)) continue;
		const int cu = std::clamp(static_cast<int>(obs[i].pixel.x() / side), 0, cols - 1);
		const int cv = std::clamp(static_cast<int>(obs[i].pixel.y() / side), 0, rows - 1);
		byCell[static_cast<std::size_t>(cu + cols * cv)].push_back(i);
	}
	std::vector<std::vector<std::size_t>> nodes;
	std::vector<std::vector<std::size_t>> cellNodes(byCell.size());
	for (std::size_t c = 0; c < byCell.size(); c++)
	{
		auto& v = byCell[c];
		std::sort(v.begin(), v.end(), [&](std::size_t a, std::size_t b) { return obs[a].depth < obs[b].depth; });
		for (std::size_t k = 0; k < v.size(); k++)
		{
			if (k == 0 || depthGap(obs[v[k - 1]].depth, obs[v[k]].depth))
			{
				cellNodes[c].push_back(nodes.size());
				nodes.emplace_back();
			}
			nodes.back().push_back(v[k]);
		}
	}
	// Nodes of 4-neighbour cells at about the same depth (median) belong to one surface.
	const auto median = [&](const std::vector<std::size_t>& v) { return obs[v[v.size() / 2]].depth; };
	std::vector<std::size_t> parent(nodes.size());
	for (std::size_t i = 0; i < parent.size(); i++) parent[i] = i;
	// Matches are sparse: a surface's cells are often one empty cell apart, so cells up to two
	// apart (either way) are neighbours.
	constexpr int kReach = 2;
	for (int r = 0; r < rows; r++)
		for (int c = 0; c < cols; c++)
			for (int dr = 0; dr <= kReach; dr++)
				for (int dc = -kReach; dc <= kReach; dc++)
				{
					if ((dr == 0 && dc <= 0) || c + dc < 0 || c + dc >= cols || r + dr >= rows) continue;
					for (std::size_t a : cellNodes[static_cast<std::size_t>(c + cols * r)])
						for (std::size_t b : cellNodes[static_cast<std::size_t>(c + dc + cols * (r + dr))])
							if (!depthGap(median(nodes[a]), median(nodes[b])))
								parent[findRoot(parent, a)] = findRoot(parent, b);
				}
	std::vector<std::vector<std::size_t>> groups;
	std::vector<std::size_t> slot(nodes.size(), nodes.size());
	for (std::size_t i = 0; i < nodes.size(); i++)
	{
		const std::size_t root = findRoot(parent, i);
		if (slot[root] == nodes.size())
		{
			slot[root] = groups.size();
			groups.emplace_back();
		}
		auto& g = groups[slot[root]];
		g.insert(g.end(), nodes[i].begin(), nodes[i].end());
	}
	return groups;
}

TPoseEstimate CGeometricDynamicCheck::rejectMovingClusters(const CPoseOptimizer& optimizer,
														   const std::vector<TPoseObservation>& obs,
														   const mrpt::img::TCamera& K, TPoseEstimate e,
														   TStats& st) const
{
	if (!opts_.enabled || !opts_.movers || !e.ok) return e;
	const std::size_t n = obs.size();
	// A group needs a few members for its mean to mean anything.
	constexpr std::size_t kMinGroup = 5;
	// At most half of the inliers leave: what stays must be the majority.
	const std::size_t initialInliers = e.numInliers;
	std::size_t leftOut = 0;  // matches of this solve's movers (st may count a caller's too)
	std::vector<bool> removed(n, false);
	using Mat36 = Eigen::Matrix<double, 3, 6, Eigen::RowMajor>;
	using Vec6 = Eigen::Matrix<double, 6, 1>;
	using Mat6 = Eigen::Matrix<double, 6, 6>;
	for (int iter = 0; iter < 3; iter++)
	{
		// Whitened residuals and their Jacobians at the estimate (closed form, left perturbation:
		// the group test only uses linear predictions, which do not depend on the parameters).
		const mrpt::poses::CPose3D Tcw = -e.cameraInWorld;
		std::vector<Eigen::Vector3d> res(n, Eigen::Vector3d::Zero());
		std::vector<Mat36> jac(n, Mat36::Zero());
		Mat6 H = Mat6::Zero();
		Vec6 b = Vec6::Zero();
		std::vector<bool> use(n, false);
		for (std::size_t i = 0; i < n; i++)
		{
			if (!e.inlier[i] || removed[i]) continue;
			reprojectionResidualJacobian(TReprojectionResidual(obs[i], K.fx(), K.fy(), K.cx(), K.cy()), Tcw, res[i],
										 jac[i]);
			H += jac[i].transpose() * jac[i];
			b += jac[i].transpose() * res[i];
			use[i] = true;
		}
		// The motion model's prior (tracking's weak term) belongs to the others' cost as it does to
		// the pose solve's: without its term in H and b the leave-one-out step undid the prior's
		// hold, and where far walls leave a turn and a shift nearly free the others' pose followed
		// a near mover, which then seemed to fit.
		Vec6 priorDev, priorInfo;
		if (optimizer.priorTerm(e.cameraInWorld, priorDev, priorInfo))
		{
			H.diagonal() += priorInfo;
			b += priorInfo.cwiseProduct(priorDev);
		}
		// Leave each group out (one Gauss-Newton step from the estimate to the minimum of the
		// others' linearised cost, (H - H_g)^-1 (b_g - b)), and see how its own members fit the
		// pose that the others give. A static surface still fits it; a mover that pulled the estimate no
		// longer does, and its members miss together.
		const auto groups = depthCoherentGroups(obs, use, K);
		std::vector<Mat6> Hgs(groups.size(), Mat6::Zero());
		std::vector<Vec6> bgs(groups.size(), Vec6::Zero());
		for (std::size_t gi = 0; gi < groups.size(); gi++)
			for (std::size_t i : groups[gi])
			{
				Hgs[gi] += jac[i].transpose() * jac[i];
				bgs[gi] += jac[i].transpose() * res[i];
			}
		// Group gi left out, and `also` with it (none: groups.size()): its statistic (n |mean
		// whitened residual|^2) and its mean metric displacement under the others' pose; false
		// where the group is too small, would take too many inliers, or the step is not finite.
		const auto test = [&](std::size_t gi, std::size_t also, double& stat, double& size)
		{
			const auto& g = groups[gi];
			// What judges the group must be the majority: with `also` out too, both count.
			const std::size_t out = leftOut + g.size() + (also < groups.size() ? groups[also].size() : 0);
			if (g.size() < kMinGroup || 2 * out > initialInliers) return false;
			Mat6 Ho = H - Hgs[gi];
			Vec6 bo = bgs[gi] - b;
			if (also < groups.size())
			{
				Ho -= Hgs[also];
				bo += bgs[also];
			}
			const Vec6 step = Ho.ldlt().solve(bo);
			if (!step.allFinite()) return false;
			// Mean whitened residual (the statistic) and mean metric displacement (the size).
			Eigen::Vector3d mean = Eigen::Vector3d::Zero(), shift = Eigen::Vector3d::Zero();
			for (std::size_t i : g)
			{
				const Eigen::Vector3d r = res[i] + jac[i] * step;
				const auto& o = obs[i];
				mean += r;
				shift += Eigen::Vector3d(r[0] * o.sigma * o.depth / K.fx(), r[1] * o.sigma * o.depth / K.fy(),
										 r[2] * o.sigmaZ);
			}
			const double m = static_cast<double>(g.size());
			mean /= m;
			shift /= m;
			stat = m * mean.squaredNorm();
			size = shift.norm();
			return true;
		};
		// The candidate is the group the others explain worst, and it leaves only if it moved far enough to count.
		// Taking the worst of those that moved far enough instead let a far wall go whose misfit was a near mover's
		// pull below the threshold (its metric size grows with depth), and the pose followed the mover.
		double worst = 0, worstSize = 0;
		std::size_t worstGroup = groups.size();
		for (std::size_t gi = 0; gi < groups.size(); gi++)
		{
			double stat = 0, size = 0;
			if (test(gi, groups.size(), stat, size) && stat > opts_.moverChi2 && stat > worst)
			{
				worst = stat;
				worstSize = size;
				worstGroup = gi;
			}
		}
		if (worstGroup == groups.size()) break;
		if (worstSize < opts_.moverShift)
		{
			// The worst group moved too little to leave, but its pull is in every other group's
			// test (and its statistic grows with its size: a large static surface with a shared
			// depth error can be the worst). The others are tested again without it too, and the
			// worst of them that moved far enough is the mover, if any.
			const std::size_t held = worstGroup;
			worst = 0;
			worstGroup = groups.size();
			for (std::size_t gi = 0; gi < groups.size(); gi++)
			{
				double stat = 0, size = 0;
				if (gi != held && test(gi, held, stat, size) && stat > opts_.moverChi2 && size >= opts_.moverShift &&
					stat > worst)
				{
					worst = stat;
					worstGroup = gi;
				}
			}
			if (worstGroup == groups.size()) break;
		}
		for (std::size_t i : groups[worstGroup]) removed[i] = true;
		st.movingGroups++;
		st.movingMatches += groups[worstGroup].size();
		leftOut += groups[worstGroup].size();
		std::vector<bool> start(n);
		for (std::size_t i = 0; i < n; i++) start[i] = e.inlier[i] && !removed[i];
		TPoseEstimate again = optimizer.refine(obs, K, e.cameraInWorld, &start);
		// A group shown to move together stays out even where single members happen to agree.
		for (std::size_t i = 0; i < n; i++)
			if (removed[i] && again.inlier[i])
			{
				again.inlier[i] = false;
				again.numInliers--;
			}
		if (!again.ok) break;
		e = again;
		e.moving = removed;
	}
	return e;
}
}  // namespace mrpt_yesslam
