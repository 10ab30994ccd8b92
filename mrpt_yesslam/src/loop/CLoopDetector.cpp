#include "mrpt_yesslam/loop/CLoopDetector.h"

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <map>
#include <random>

#include "mrpt_yesslam/feature/COrbMatcher.h"
#include "mrpt_yesslam/geometry/CPinholeCamera.h"
#include "mrpt_yesslam/geometry/CPoseOptimizer.h"
#include "mrpt_yesslam/util/Error.h"

namespace mrpt_yesslam
{
COptionTable CLoopDetector::TOptions::table()
{
	COptionTable t("LoopClosing");
	t.flag("enabled", enabled, "detect and close loops (--no-loop-closure sets false)");
	t.text("vocabulary", vocabulary,
		   "ORB vocabulary file (yesslam-vocab); empty = the shipped share/mrpt_yesslam/vocabulary/orb_k10_L5.yvoc");
	t.integer("directLevel", directLevel, 0, 10,
			  "tree depth of the direct index used to match keyframes (ORB-SLAM2: 2 of 6 levels)");
	t.integer("covisibleWeight", covisibleWeight, 0, 100000,
			  "N_cov: keyframes sharing more map points with the current one are covisible, never loop candidates");
	t.real("alphaRich", alphaRich, 0, 1,
		   "eq. 20: weight of the BoW score in S_Loop when the keyframe has at least richObjects semantic objects");
	t.real("alphaPoor", alphaPoor, 0, 1, "eq. 20: weight of the BoW score in S_Loop with fewer objects");
	t.flag("normaliseBow", normaliseBow,
		   "divide s_BoW by the keyframe's best score with its covisible keyframes before eq. 19 (DBoW2's normalised "
		   "score), so it weighs as much as S_G");
	t.count("richObjects", richObjects, 0, 1000, "N_sw threshold of eq. 20 (static semantic objects in the keyframe)");
	t.count("consistency", consistency, 1, 100,
			"N_c: consecutive keyframes whose candidate groups must overlap (eq. 21-22)");
	t.real("minLoopAge", minLoopAge, 0, 1e6,
		   "candidates must be at least this many seconds older than the keyframe (a place left moments ago is "
		   "tracking's, not a loop)");
	t.count("minKeyFrames", minKeyFrames, 0, 1000000, "no loop detection before the map has this many keyframes");
	t.text("matching", matching,
		   "how a loop pair's keypoints are first matched: all (every static keypoint with depth against every other) "
		   "or bow (within the vocabulary's direct-index nodes, ORB-SLAM2's SearchByBoW)",
		   {"all", "bow"});
	t.integer("maxHamming", maxHamming, 0, 256,
			  "largest descriptor distance when matching keyframes (ORB-SLAM2's TH_LOW)");
	t.real("ratio", ratio, 0.1, 1, "nearest / second-nearest descriptor distance ratio when matching keyframes");
	t.count("minMatches", minMatches, 3, 100000, "matched keypoints with depth needed to try RANSAC");
	t.count("minInliers", minInliers, 3, 100000, "RANSAC inliers needed to accept the transform");
	t.count("ransacIterations", ransacIterations, 1, 1000000, "RANSAC iterations of the 3D-3D transform");
	t.count("minSeedInliers", minSeedInliers, 3, 100000,
			"RANSAC inliers that let guided matching look for more (minInliers must then agree)");
	t.real("guidedRadius", guidedRadius, 0, 100,
		   "guided matching search radius after RANSAC, pixels at level 0 (ORB-SLAM2's SearchBySim3: 7.5; 0 = none)");
	t.integer("guidedHamming", guidedHamming, 0, 256,
			  "guided matching's largest descriptor distance (ORB-SLAM2's TH_HIGH)");
	t.count("minProjectionMatches", minProjectionMatches, 0, 100000,
			"map points of the loop's place matched with the corrected pose, needed to accept");
	t.real("projectionRadius", projectionRadius, 0.5, 1000, "pixel radius (level 0) of that search");
	return t;
}

CLoopDetector::CLoopDetector(const TOptions& opts, const CSparseMap& map, std::shared_ptr<const CVocabulary> vocabulary,
							 std::shared_ptr<const CBowDatabase> database,
							 const CSemanticKeyFrameSelector::TOptions& semantic, double scaleFactor, double maxDepth,
							 const TDepthNoise& depthNoise)
	: opts_(opts),
	  map_(map),
	  vocabulary_(std::move(vocabulary)),
	  database_(std::move(database)),
	  semantic_(semantic),
	  scaleFactor_(scaleFactor),
	  maxDepth_(maxDepth),
	  noise_(depthNoise)
{
	if (!vocabulary_ || !database_) throw std::invalid_argument("CLoopDetector needs a vocabulary and a database");
}

namespace
{
std::vector<TDetection> staticDetections(const CKeyFrame& k)
{
	std::vector<TDetection> out;
	for (const auto& d : k.detections)
		if (!d.dynamic) out.push_back(d);
	return out;
}

// b keypoint -> (distance, a keypoint): one keypoint of b answers one of a, the nearest.
using TNearestForB = std::map<std::size_t, std::pair<int, std::size_t>>;

// Keeps a's keypoint `i` as the match of b's keypoint `two.index` unless a nearer one has it.
void keep(TNearestForB& bestForB, const TBestTwo& two, std::size_t i)
{
	const auto [it, fresh] = bestForB.try_emplace(static_cast<std::size_t>(two.index), two.best, i);
	if (!fresh && two.best < it->second.first) it->second = {two.best, i};
}
}  // namespace

double CLoopDetector::semanticSimilarity(const CKeyFrame& a, const CKeyFrame& b) const
{
	const auto da = staticDetections(a), db = staticDetections(b);
	const cv::Size size(static_cast<int>(a.camera.ncols), static_cast<int>(a.camera.nrows));
	const double J = jaccardSimilarity(semanticRegionVectors(da, size, semantic_.gridCols, semantic_.gridRows),
									   semanticRegionVectors(db, size, semantic_.gridCols, semantic_.gridRows));
	return globalSimilarity(J, areaSimilarity(da, db, semantic_.etaAsWritten), semantic_.gamma);
}

double CLoopDetector::alphaOf(const CKeyFrame& k) const
{
	return staticDetections(k).size() >= opts_.richObjects ? opts_.alphaRich : opts_.alphaPoor;
}

double CLoopDetector::referenceScore(const CKeyFrame& k) const
{
	double best = 0;
	if (!k.bow) return 0;
	for (const auto& [other, w] : k.connections)
	{
		const CKeyFrame o = map_.keyFrame(other);
		if (!o.bad && o.bow) best = std::max(best, CVocabulary::score(k.bow->words, o.bow->words));
	}
	return best;
}

double CLoopDetector::loopScore(const CKeyFrame& a, const CKeyFrame& b, double reference) const
{
	if (!a.bow || !b.bow) return 0;
	const double alpha = alphaOf(a);
	double s = CVocabulary::score(a.bow->words, b.bow->words);
	if (opts_.normaliseBow)
	{
		if (reference < 0) reference = referenceScore(a);
		if (reference > 0) s = std::min(1.0, s / reference);
	}
	return alpha * s + (1 - alpha) * semanticSimilarity(a, b);
}

std::optional<TLoop> CLoopDetector::detect(TKeyFrameId id)
{
	if (!opts_.enabled || map_.numKeyFrames() < opts_.minKeyFrames || !map_.hasKeyFrame(id) || map_.isBad(id))
	{
		groups_.clear();
		return std::nullopt;
	}
	const CKeyFrame kf = map_.keyFrame(id);
	if (!kf.bow) return std::nullopt;
	stats_.queries++;
	// Covisible keyframes are the same place seen moments ago, not a loop: excluded, and the lowest
	// score among them is the bar a candidate must clear (ORB-SLAM2's minScore).
	std::set<TKeyFrameId> exclude{id};
	const double reference = opts_.normaliseBow ? referenceScore(kf) : 0;
	double minScore = 1;
	bool anyNeighbour = false;
	for (const auto& [other, weight] : kf.connections)
	{
		exclude.insert(other);
		if (weight < opts_.covisibleWeight) continue;
		const CKeyFrame o = map_.keyFrame(other);
		if (o.bad || !o.bow) continue;
		minScore = std::min(minScore, loopScore(kf, o, reference));
		anyNeighbour = true;
	}
	if (!anyNeighbour) minScore = 0;
	// Every candidate appearance gives is recorded with where it stopped (loop_candidates.csv).
	const auto record = [&](const TKeyFrameId c, double stamp, double bow, double score, const char* stage)
	{
		TLoopCandidate r;
		r.query = id, r.candidate = c, r.queryStamp = kf.timestamp, r.candidateStamp = stamp;
		r.bowScore = bow, r.loopScore = score, r.minScore = minScore, r.stage = stage;
		candidates_.push_back(r);
		return candidates_.size() - 1;
	};
	// What the query would have found without the covisible ones excluded: those are recorded so.
	for (const auto& c : database_->query(kf.bow->words, {id}))
		if (exclude.count(c.keyFrame) && map_.hasKeyFrame(c.keyFrame) && !map_.isBad(c.keyFrame))
			record(c.keyFrame, map_.keyFrame(c.keyFrame).timestamp, c.score, 0, "covisible");
	auto cands = database_->query(kf.bow->words, exclude);
	std::vector<TBowCandidate> scored;
	std::map<TKeyFrameId, std::size_t> recordOf;  // scored candidate -> its record
	for (auto& c : cands)
	{
		if (!map_.hasKeyFrame(c.keyFrame) || map_.isBad(c.keyFrame)) continue;
		const CKeyFrame o = map_.keyFrame(c.keyFrame);
		if (o.id >= sessionStart_ && kf.timestamp - o.timestamp < opts_.minLoopAge)
		{
			record(o.id, o.timestamp, c.score, 0, "young");
			continue;
		}
		const double bow = c.score;
		c.score = loopScore(kf, o, reference);
		const std::size_t r = record(o.id, o.timestamp, bow, c.score, "below_min_score");
		if (c.score < minScore) continue;
		scored.push_back(c);
		recordOf[o.id] = r;
	}
	const auto grouped = groupCandidates(scored, map_);
	for (auto& [kfId, r] : recordOf) candidates_[r].stage = "not_group_best";

	// Consistency (eq. 21-22): each candidate's group against the previous keyframe's groups.
	std::vector<TGroup> current;
	std::vector<TKeyFrameId> consistent;
	for (const auto& c : grouped)
	{
		TGroup g;
		g.members.insert(c.keyFrame);
		for (const auto n : map_.covisible(c.keyFrame, 1000000, opts_.covisibleWeight)) g.members.insert(n);
		std::size_t best = 0;
		for (const auto& prev : groups_)
			if (std::any_of(g.members.begin(), g.members.end(),
							[&](TKeyFrameId m) { return prev.members.count(m) != 0; }))
				best = std::max(best, prev.consistency);
		g.consistency = best + 1;
		if (g.consistency >= opts_.consistency) consistent.push_back(c.keyFrame);
		if (const auto it = recordOf.find(c.keyFrame); it != recordOf.end())
			candidates_[it->second].stage = g.consistency >= opts_.consistency ? "untried" : "inconsistent";
		current.push_back(std::move(g));
	}
	groups_ = std::move(current);
	if (consistent.empty()) return std::nullopt;
	stats_.consistent++;
	for (const auto c : consistent)
		if (auto loop = verifyRecorded(id, c, recordOf))
		{
			loop->score = loopScore(kf, map_.keyFrame(c));
			stats_.accepted++;
			groups_.clear();  // a closed loop starts the consistency count afresh (ORB-SLAM2)
			return loop;
		}
	stats_.rejectedGeometry++;
	return std::nullopt;
}

std::optional<TLoop> CLoopDetector::verifyRecorded(TKeyFrameId id, TKeyFrameId candidate,
												   const std::map<TKeyFrameId, std::size_t>& recordOf)
{
	TLoopCandidate outcome;
	auto loop = verify(id, candidate, &outcome);
	if (const auto it = recordOf.find(candidate); it != recordOf.end())
	{
		TLoopCandidate& r = candidates_[it->second];
		r.stage = outcome.stage, r.matches = outcome.matches, r.inliers = outcome.inliers;
	}
	return loop;
}

std::optional<TLoop> CLoopDetector::verify(TKeyFrameId id, TKeyFrameId candidate, TLoopCandidate* outcome) const
{
	TLoopCandidate scratch;
	TLoopCandidate& out = outcome ? *outcome : scratch;
	const auto stop = [&](const char* stage, std::size_t inliers)
	{
		out.stage = stage;
		out.inliers = inliers;
		return std::nullopt;
	};
	const CKeyFrame a = map_.keyFrame(id), b = map_.keyFrame(candidate);
	if (a.bad || b.bad || !a.bow || !b.bow || !a.features || !b.features) return stop("gone", 0);
	const TFeatures &fa = *a.features, &fb = *b.features;
	const auto distance = [&](std::size_t i, std::size_t j)
	{
		return orbDistance(fa.descriptors.ptr<unsigned char>(static_cast<int>(i)),
						   fb.descriptors.ptr<unsigned char>(static_cast<int>(j)));
	};
	// 1. Keypoints with depth matched: every usable pair ([LoopClosing] matching = all), or within the direct index's
	// nodes (bow, ORB-SLAM2's SearchByBoW), a shortcut for thousands of monocular keypoints: among the few static ones
	// of an RGB-D keyframe with people in view it found a fraction of the pairs on the real Bonn slice.
	std::vector<std::pair<std::size_t, std::size_t>> matches;
	{
		TNearestForB bestForB;
		const auto matchOne = [&](std::size_t i, const auto& candidatesOfB)
		{
			if (!fa.usable(i, maxDepth_)) return;
			TBestTwo two;
			for (const auto j : candidatesOfB)
				if (fb.usable(j, maxDepth_)) two.add(distance(i, j), static_cast<int>(j));
			if (two.acceptedStrictly(opts_.maxHamming, opts_.ratio)) keep(bestForB, two, i);
		};
		if (opts_.matching == "all")
		{
			std::vector<std::size_t> all;
			for (std::size_t j = 0; j < fb.keypoints.size(); j++)
				if (fb.usable(j, maxDepth_)) all.push_back(j);
			for (std::size_t i = 0; i < fa.keypoints.size(); i++) matchOne(i, all);
		}
		else
		{
			auto ia = a.bow->direct.begin(), ib = b.bow->direct.begin();
			while (ia != a.bow->direct.end() && ib != b.bow->direct.end())
			{
				if (ia->first < ib->first)
					++ia;
				else if (ib->first < ia->first)
					++ib;
				else
				{
					for (const auto i : ia->second) matchOne(i, ib->second);
					++ia, ++ib;
				}
			}
		}
		for (const auto& [j, di] : bestForB) matches.emplace_back(di.second, j);
	}
	out.matches = matches.size();
	if (matches.size() < opts_.minMatches) return stop("few_matches", 0);

	// 2. RANSAC on the 3D points (eq. 23, s = 1): p_b = R p_a + t.
	const CPinholeCamera Ka(a.camera), Kb(b.camera);
	const auto sigmaOf = [&](const cv::KeyPoint& k) { return std::pow(scaleFactor_, std::max(0, k.octave)); };
	// Keypoint i of the current keyframe seeing `point` (in the frame the pose is solved in), for
	// the pose solves of steps 4 and 6: its depth a weak term with the sensor's noise.
	const auto observation = [&](std::size_t i, const Eigen::Vector3d& point)
	{
		TPoseObservation o;
		o.world = point;
		const auto& kp = fa.keypoints[i];
		o.pixel = {kp.pt.x, kp.pt.y};
		o.sigma = sigmaOf(kp);
		o.depth = fa.depth[i];
		o.sigmaZ = noise_.measures(o.depth) ? noise_.sigma(o.depth) : 0.0;
		return o;
	};
	std::vector<Eigen::Vector3d> pa, pb;
	const auto setPoints = [&]
	{
		pa.clear(), pb.clear();
		for (const auto& [i, j] : matches)
		{
			const cv::Point3d x = a.backProject(i), y = b.backProject(j);
			pa.emplace_back(x.x, x.y, x.z);
			pb.emplace_back(y.x, y.y, y.z);
		}
	};
	setPoints();
	auto inliersOf = [&](const Eigen::Matrix3d& R, const Eigen::Vector3d& t)
	{
		std::vector<std::size_t> in;
		for (std::size_t k = 0; k < pa.size(); k++)
		{
			// ORB-SLAM2's Sim3Solver::CheckInliers: the reprojection error in both keyframes, chi2
			// with 2 degrees of freedom at 99 % (9.21 sigma^2).
			const Eigen::Vector3d qb = R * pa[k] + t, qa = R.transpose() * (pb[k] - t);
			double u, v;
			if (!Kb.project(qb.x(), qb.y(), qb.z(), u, v)) continue;
			const auto& kb = fb.keypoints[matches[k].second];
			const double sb = sigmaOf(kb);
			if ((u - kb.pt.x) * (u - kb.pt.x) + (v - kb.pt.y) * (v - kb.pt.y) > 9.21 * sb * sb) continue;
			if (!Ka.project(qa.x(), qa.y(), qa.z(), u, v)) continue;
			const auto& ka = fa.keypoints[matches[k].first];
			const double sa = sigmaOf(ka);
			if ((u - ka.pt.x) * (u - ka.pt.x) + (v - ka.pt.y) * (v - ka.pt.y) > 9.21 * sa * sa) continue;
			in.push_back(k);
		}
		return in;
	};
	std::mt19937 rng(static_cast<unsigned>(id * 7919 + candidate));
	std::uniform_int_distribution<std::size_t> pick(0, pa.size() - 1);
	std::vector<std::size_t> bestIn;
	for (std::size_t it = 0; it < opts_.ransacIterations; it++)
	{
		std::size_t s[3];
		s[0] = pick(rng);
		do s[1] = pick(rng);
		while (s[1] == s[0]);
		do s[2] = pick(rng);
		while (s[2] == s[0] || s[2] == s[1]);
		Eigen::Matrix3d R;
		Eigen::Vector3d t;
		if (!rigidMotionFromPoints({pb[s[0]], pb[s[1]], pb[s[2]]}, {pa[s[0]], pa[s[1]], pa[s[2]]}, R, t)) continue;
		auto in = inliersOf(R, t);
		if (in.size() > bestIn.size()) bestIn = std::move(in);
	}
	if (bestIn.size() < std::min(opts_.minSeedInliers, opts_.minInliers)) return stop("ransac", bestIn.size());
	Eigen::Matrix3d R;
	Eigen::Vector3d t;
	{
		std::vector<Eigen::Vector3d> qa, qb;
		for (const auto k : bestIn) qa.push_back(pa[k]), qb.push_back(pb[k]);
		if (!rigidMotionFromPoints(qb, qa, R, t)) return stop("ransac", bestIn.size());
	}

	// 3. Guided matching (ORB-SLAM2's SearchBySim3): with the seed transform every usable keypoint of
	// `a` is searched for where it lands in `b` (radius guidedRadius x its scale, the looser
	// descriptor threshold of tracking); the seed's few matches become the many a true revisit has.
	if (opts_.guidedRadius > 0)
	{
		std::vector<std::vector<std::size_t>> grid;  // b's usable keypoints in 32-px cells
		const int cell = 32, gw = static_cast<int>(b.camera.ncols) / cell + 1,
				  gh = static_cast<int>(b.camera.nrows) / cell + 1;
		grid.resize(static_cast<std::size_t>(gw * gh));
		for (std::size_t j = 0; j < fb.keypoints.size(); j++)
			if (fb.usable(j, maxDepth_))
			{
				const int gx = std::clamp(static_cast<int>(fb.keypoints[j].pt.x) / cell, 0, gw - 1),
						  gy = std::clamp(static_cast<int>(fb.keypoints[j].pt.y) / cell, 0, gh - 1);
				grid[static_cast<std::size_t>(gy * gw + gx)].push_back(j);
			}
		TNearestForB bestForB;
		for (std::size_t i = 0; i < fa.keypoints.size(); i++)
		{
			if (!fa.usable(i, maxDepth_)) continue;
			const cv::Point3d x = a.backProject(i);
			const Eigen::Vector3d q = R * Eigen::Vector3d(x.x, x.y, x.z) + t;
			double u, v;
			if (!Kb.project(q.x(), q.y(), q.z(), u, v)) continue;
			const double r = opts_.guidedRadius * sigmaOf(fa.keypoints[i]);
			TBestTwo two;
			for (int gy = std::max(0, static_cast<int>((v - r) / cell));
				 gy <= std::min(gh - 1, static_cast<int>((v + r) / cell)); gy++)
				for (int gx = std::max(0, static_cast<int>((u - r) / cell));
					 gx <= std::min(gw - 1, static_cast<int>((u + r) / cell)); gx++)
					for (const auto j : grid[static_cast<std::size_t>(gy * gw + gx)])
					{
						const auto& kb = fb.keypoints[j];
						if ((kb.pt.x - u) * (kb.pt.x - u) + (kb.pt.y - v) * (kb.pt.y - v) > r * r) continue;
						two.add(distance(i, j), static_cast<int>(j));
					}
			if (two.acceptedStrictly(opts_.guidedHamming, 0.9)) keep(bestForB, two, i);
		}
		matches.clear();
		for (const auto& [j, di] : bestForB) matches.emplace_back(di.second, j);
		out.matches = matches.size();
		setPoints();
		bestIn = inliersOf(R, t);
	}
	// Refined on all inliers, and the inliers recounted with the refined transform.
	for (int refine = 0; refine < 2; refine++)
	{
		if (bestIn.size() < opts_.minInliers) return stop("ransac", bestIn.size());
		std::vector<Eigen::Vector3d> qa, qb;
		for (const auto k : bestIn) qa.push_back(pa[k]), qb.push_back(pb[k]);
		if (!rigidMotionFromPoints(qb, qa, R, t)) return stop("ransac", bestIn.size());
		bestIn = inliersOf(R, t);
	}
	if (bestIn.size() < opts_.minInliers) return stop("ransac", bestIn.size());

	TLoop loop;
	loop.current = id;
	loop.matched = candidate;
	loop.ransacInliers = bestIn.size();
	mrpt::math::CMatrixDouble44 T;
	T.setIdentity();
	for (int r = 0; r < 3; r++)
	{
		for (int c = 0; c < 3; c++) T(r, c) = R(r, c);
		T(r, 3) = t(r);
	}
	loop.relative = mrpt::poses::CPose3D(T);  // T_b_a: the current camera in the matched one's frame
	// 4. The relative pose from the reprojection of the matched place's points into the current keyframe, with their
	// depth as a weak term (the pose solve of tracking): the 3D-3D fit above weighs every point's depth error, which
	// grows faster than z, and on the real Bonn slice reprojection brought its pose much nearer the ground truth's.
	// With the sensor's depth noise at 0 (paper.ini) on reprojection alone: the solve and its inlier
	// gate still run, as they did when the loop had its own depth option.
	{
		std::vector<TPoseObservation> obs;
		for (const auto k : bestIn) obs.push_back(observation(matches[k].first, pb[k]));
		const TPoseEstimate e = CPoseOptimizer().refine(obs, a.camera, loop.relative);
		if (!e.ok || e.numInliers < opts_.minInliers) return stop("pose_solve", e.ok ? e.numInliers : 0);
		loop.relative = e.cameraInWorld;
		loop.ransacInliers = e.numInliers;
	}
	if (verifyHook_) verifyHook_();

	// 5. The place's map points (the candidate and its covisible keyframes) projected with the
	// corrected pose must find enough of the current keyframe's keypoints. The candidate's pose is
	// read with the points, under one lock: detection runs beside local mapping and the global BA,
	// and a pose read at the start (b's) with points read after a BA moved the place would put
	// that move into the loop's relative pose (a review's finding).
	std::vector<TKeyFrameId> place{candidate};
	for (const auto n : map_.covisible(candidate, 10)) place.push_back(n);
	mrpt::poses::CPose3D placePose;
	const TLocalMapPoints pts = map_.pointsOfKeyFrames(place, candidate, placePose);
	loop.correctedPose = placePose + loop.relative;
	TFrame f;
	f.camera = a.camera;
	f.features = fa;
	f.mapPoints.assign(fa.keypoints.size(), -1);
	const COrbMatcher matcher(opts_.maxHamming, opts_.ratio);
	const auto found =
		matcher.searchByProjection(f, loop.correctedPose, pts, opts_.projectionRadius, nullptr, false, scaleFactor_);
	if (found.size() < opts_.minProjectionMatches) return stop("projection", found.size());
	// 6. The pose re-solved on the search's pairs, which passed the matcher's view and scale checks, not only the fit's
	// loose gate (ORB-SLAM2 keeps the fit's pose): nearer the ground truth on the real Bonn slice's revisits. Taken,
	// and only its pairs fused, where as many agree as the count asked; else the fit and all pairs stay.
	std::vector<bool> agrees(found.size(), true);
	{
		std::vector<TPoseObservation> obs;
		for (const auto& m : found)
		{
			const auto& P = pts.positions[m.point];
			obs.push_back(observation(m.keypoint, {P.x, P.y, P.z}));
		}
		const TPoseEstimate e = CPoseOptimizer().refine(obs, a.camera, loop.correctedPose);
		if (e.ok && e.numInliers >= std::max(opts_.minInliers, opts_.minProjectionMatches))
		{
			loop.correctedPose = e.cameraInWorld;
			loop.relative = (-placePose) + loop.correctedPose;
			agrees = e.inlier;
		}
	}
	for (std::size_t k = 0; k < found.size(); k++)
		if (agrees[k]) loop.pointMatches.emplace_back(found[k].keypoint, pts.ids[found[k].point]);
	out.stage = "accepted";
	out.inliers = loop.ransacInliers;
	return loop;
}
}  // namespace mrpt_yesslam
