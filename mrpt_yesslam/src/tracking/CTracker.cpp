#include "mrpt_yesslam/tracking/CTracker.h"

#include <mrpt/config/CConfigFileBase.h>
#include <mrpt/poses/Lie/SE.h>
#include <mrpt/poses/Lie/SO.h>

#include <algorithm>
#include <limits>
#include <numeric>

#include "mrpt_yesslam/geometry/RelativeMotion.h"

namespace mrpt_yesslam
{
COptionTable CTracker::TOptions::table()
{
	COptionTable t("Tracking");
	t.append(pose.table());
	t.real("maxDepth", maxDepth, 0.1, 100,
		   "keypoints deeper than this are not used (nearer ones are weighted by the depth noise model), m");
	t.real("motionRadius", motionRadius, 1, 1000,
		   "pixel search radius around motion-model projections (ORB-SLAM2: 15)");
	t.real("localRadius", localRadius, 0.5, 1000, "pixel search radius for the local map");
	t.flag("viewChecks", viewChecks,
		   "local-map search as ORB-SLAM2's: a map point is in view only within its pyramid's distance range and 60 "
		   "degrees of its mean viewing direction, searched at the level its distance predicts");
	t.integer("maxHamming", maxHamming, 0, 256, "largest descriptor distance of a match (ORB-SLAM2's TH_HIGH)");
	t.real("ratio", ratio, 0.1, 1, "nearest / second-nearest distance ratio for projection search (ORB-SLAM2: 0.9)");
	t.count("localKeyFrames", localKeyFrames, 1, 10000, "most keyframes in the local map (ORB-SLAM2: 80)");
	t.count("localNeighbours", localNeighbours, 0, 1000,
			"best covisible keyframes added around each keyframe that sees the frame's matches");
	t.count("minTrackedInliers", minTrackedInliers, 3, 100000,
			"fewer inliers against the local map: tracking failed for this frame");
	t.count("weakInliers", weakInliers, 0, 100000,
			"a solution on fewer inliers must lie within priorDeparture(Deg) of the motion model's prediction, or the "
			"frame coasts (0 = off)");
	t.real("priorDeparture", priorDeparture, 0, 10,
		   "m: how far a weak solution may lie from the motion model's prediction, per frame interval since the last "
		   "frame");
	t.real("priorDepartureDeg", priorDepartureDeg, 0, 180,
		   "degrees: how far a weak solution may turn from the motion model's prediction, per frame interval since the "
		   "last frame");
	t.count("relocInliers", relocInliers, 0, 100000,
			"a relocalisation on at least this many inliers is not held to the prediction tracking failed to confirm "
			"(ORB-SLAM2: 50; 0 = held as any other solution)");
	t.real("motionPriorSigma", motionPriorSigma, 0, 10,
		   "m: the motion model's prediction as a weak term of the pose solve, per camera axis (this or "
		   "motionPriorSigmaDeg 0 = no prior)");
	t.real("motionPriorSigmaDeg", motionPriorSigmaDeg, 0, 180,
		   "degrees: the same for the rotation (this or motionPriorSigma 0 = no prior)");
	t.count("priorLostFrames", priorLostFrames, 0, 1000,
			"for this many lost frames since the motion was last measured, the coasted prediction still judges weak "
			"solutions, with 1 + n times the departures (0 = only a prediction from tracked frames does)");
	t.count("relocKeyFrames", relocKeyFrames, 0, 1000000,
			"most keyframes relocalisation tries: the best place-recognition candidates, else the newest (0 = all)");
	t.count("lostCoastFrames", lostCoastFrames, 0, 100000,
			"lost frames that still continue the last velocity (then the pose is held)");
	t.real("lostDamping", lostDamping, 0, 1,
		   "each lost frame the velocity is multiplied by this (0 = hold the pose at once)");
	t.count("lostVelocityFrames", lostVelocityFrames, 1, 1000,
			"lost frames continue the mean velocity of this many last tracked frames (1: the last one alone)");
	t.integer("seeThroughFrames", seeThroughFrames, 0, 1000,
			  "a map point with farther surfaces measured around it in this many consecutive frames has moved away: "
			  "erased (0 = never)");
	t.flag("depthMoment", depthMoment,
		   "where the depth image was taken at another moment than the colour image (TUM folders: depth.txt's stamps), "
		   "keypoint depth is moved to the colour image's moment with the motion model");
	t.real("rollingShutter", rollingShutter, -1, 0.1,
		   "the colour camera's rolling-shutter readout, seconds from the first row to the last: keypoints are moved "
		   "to the middle row's moment with the motion model (0 = global shutter; -1 = auto: a yesslam-sim sequence's "
		   "own (meta.json), else the camera's where known: 0.028 for the TUM presets and Bonn folders (Kinect v1, "
		   "Xtion), a camera file's readout line; 0 where not known (rawlogs, OpenNI2 devices); never more than the "
		   "time since the previous frame)");
	return t;
}

std::vector<TPoseObservation> makePoseObservations(const TFrame& f, const std::vector<TMatch>& m,
												   const TLocalMapPoints& pts, double scaleFactor,
												   const TDepthNoise& depthNoise)
{
	std::vector<TPoseObservation> obs;
	obs.reserve(m.size());
	for (const auto& x : m)
	{
		TPoseObservation o;
		const auto& P = pts.positions[x.point];
		o.world = {P.x, P.y, P.z};
		const auto& kp = f.features.keypoints[x.keypoint];
		o.pixel = {kp.pt.x, kp.pt.y};
		o.sigma = std::pow(scaleFactor, std::max(0, kp.octave));
		const double z = x.keypoint < f.features.depth.size() ? f.features.depth[x.keypoint] : 0.0;
		if (depthNoise.used() && z > 0)
		{
			// The depth stays known beyond [Camera] farDepth (the mover check sizes and groups
			// keypoints by it); only its residual leaves the solve there (sigmaZ 0).
			o.depth = z;
			// The level-0 sigma, unlike bundle adjustment's (scaled with the pixel's): scaled here too, it made the
			// real Bonn slice worse, with the former models and the one model alike (docs/benchmarks.md, "One
			// depth-noise model").
			if (depthNoise.measures(z)) o.sigmaZ = depthNoise.sigma(z);
		}
		obs.push_back(o);
	}
	return obs;
}

CTracker::CTracker(const TOptions& opts, CSparseMap& map, double scaleFactor,
				   const CGeometricDynamicCheck::TOptions& check, const TDepthNoise& depthNoise)
	: opts_(opts),
	  map_(map),
	  optimizer_(opts.pose),
	  check_(check),
	  matcher_(opts.maxHamming, opts.ratio),
	  scaleFactor_(scaleFactor),
	  noise_(depthNoise)
{
}

std::optional<TKeyFrameId> CTracker::referenceKeyFrame() const
{
	if (!refKf_) return std::nullopt;
	return map_.goodAncestor(*refKf_);
}

void CTracker::setReferenceKeyFrame(TKeyFrameId kf, std::optional<std::size_t> fromFrame)
{
	refKf_ = kf;
	if (fromFrame && tracked_ && tracked_->frameId == *fromFrame) tracked_->anchor = {kf, mrpt::poses::CPose3D()};
}

std::optional<TAnchor> CTracker::anchorOf(std::size_t frameId) const
{
	if (!tracked_ || tracked_->frameId != frameId) return std::nullopt;
	return tracked_->anchor;
}

void CTracker::anchor(const TFrame& f, const mrpt::poses::CPose3D& base)
{
	TTracked t;
	t.frameId = f.id;
	t.generation = map_.generation();
	t.base = base;
	t.anchor.refKf = referenceKeyFrame();
	t.anchor.relative = t.anchor.refKf ? f.pose - map_.keyFramePose(*t.anchor.refKf) : f.pose;
	tracked_ = t;
}

TPoseEstimate CTracker::refineWith(const TFrame& f, const std::vector<TMatch>& m, const TLocalMapPoints& pts,
								   const mrpt::poses::CPose3D& guess) const
{
	std::vector<bool> uncertain(m.size());
	for (std::size_t k = 0; k < m.size(); k++) uncertain[k] = f.features.isUncertain(m[k].keypoint);
	CPoseOptimizer withPrior = optimizer_;  // the options alone: cheap
	withPrior.setPrior(motionPrior_);
	return check_.refine(withPrior, makePoseObservations(f, m, pts, scaleFactor_, noise_), uncertain, f.camera, guess);
}

TLocalMapPoints CTracker::lastFramePoints(const mrpt::poses::CPose3D& lastPose) const
{
	TLocalMapPoints out;
	if (!last_) return out;
	std::vector<TPointId> ids;
	std::vector<std::size_t> temporary;
	for (std::size_t i = 0; i < last_->size(); i++)
	{
		if (i < last_->mapPoints.size() && last_->mapPoints[i] >= 0)
			ids.push_back(last_->mapPoints[i]);
		else if (last_->usable(i, opts_.maxDepth))
			temporary.push_back(i);
	}
	out = map_.pointsById(ids);
	for (std::size_t i : temporary)
	{
		const cv::Point3d pc = last_->backProject(i);
		double gx, gy, gz;
		lastPose.composePoint(pc.x, pc.y, pc.z, gx, gy, gz);
		out.ids.push_back(-1);
		out.positions.push_back({gx, gy, gz});
		out.descriptors.push_back(last_->features.descriptors.row(static_cast<int>(i)));
	}
	return out;
}

bool CTracker::trackLocalMap(TFrame& f, const mrpt::poses::CPose3D& guess, const std::vector<TPointId>& seeds,
							 TResult& r, double radius, bool relocalising)
{
	const auto ref = referenceKeyFrame();
	if (!ref) return false;
	// ORB-SLAM2's local map: the keyframes that see what the frame already matched and their
	// neighbours, not only the newest keyframe's. Back in a place mapped long ago, tracking then
	// finds the old points again instead of the map growing a second copy of the place.
	const std::vector<TKeyFrameId> kfs = map_.localKeyFrames(seeds, *ref, opts_.localKeyFrames, opts_.localNeighbours);
	if (kfs.empty()) return false;
	const TLocalMapPoints local = map_.pointsOfKeyFrames(kfs);
	std::vector<std::size_t> inView;
	const auto m = matcher_.searchByProjection(f, guess, local, radius, &inView, false, scaleFactor_, opts_.viewChecks);
	r.localMatches = m.size();
	const TPoseEstimate e = refineWith(f, m, local, guess);
	if (!e.ok || e.numInliers < opts_.minTrackedInliers) return false;
	// Before anything is learnt from the frame (see-through counts, movers): a refused pose would
	// erase good points.
	if (!plausible(e.cameraInWorld, e.numInliers, r, relocalising)) return false;
	f.pose = e.cameraInWorld;
	f.mapPoints.assign(f.size(), -1);
	std::vector<TPointId> visible, found;
	for (std::size_t j : inView) visible.push_back(local.ids[j]);
	for (std::size_t k = 0; k < m.size(); k++)
		if (e.inlier[k])
		{
			f.mapPoints[m[k].keypoint] = local.ids[m[k].point];
			found.push_back(local.ids[m[k].point]);
		}
	if (!readOnly_)
		r.movingPointsErased +=
			map_.countTracking(visible, found, seenThrough(f, local, inView, found), opts_.seeThroughFrames);
	// Matches of a group the check found moving: their map points are culled (a person who stood
	// still and walks away leaves none behind), the mover's keypoints never become map points, and
	// where it is stays uncertain for the next frames.
	std::vector<std::size_t> moving;
	for (std::size_t k = 0; k < m.size(); k++)
		if (e.isMoving(k))
		{
			moving.push_back(m[k].keypoint);
			if (!readOnly_) r.movingPointsErased += map_.erasePoint(local.ids[m[k].point]);
		}
	updateMovers(f, moving);
	refKf_ = kfs.front();  // the keyframe sharing most points with the frame (ORB-SLAM2)
	f.numInliers = e.numInliers;
	r.inliers = e.numInliers;
	return true;
}

std::vector<TPointId> CTracker::seenThrough(const TFrame& f, const TLocalMapPoints& local,
											const std::vector<std::size_t>& inView,
											const std::vector<TPointId>& found) const
{
	std::vector<TPointId> out;
	if (opts_.seeThroughFrames <= 0) return out;
	// The nearest keypoint depth (every keypoint: a person in front is a surface too) per cell.
	constexpr int kCell = 16;
	const int cols = (static_cast<int>(f.camera.ncols) + kCell - 1) / kCell,
			  rows = (static_cast<int>(f.camera.nrows) + kCell - 1) / kCell;
	if (cols <= 0 || rows <= 0) return out;
	std::vector<float> nearest(static_cast<std::size_t>(cols * rows), std::numeric_limits<float>::infinity());
	std::vector<int> count(nearest.size(), 0);
	for (std::size_t i = 0; i < f.size(); i++)
	{
		const float z = i < f.features.depth.size() ? f.features.depth[i] : 0.f;
		const auto& p = f.features.keypoints[i].pt;
		const int cu = static_cast<int>(p.x) / kCell, cv = static_cast<int>(p.y) / kCell;
		if (!(z > 0) || cu < 0 || cv < 0 || cu >= cols || cv >= rows) continue;
		const auto c = static_cast<std::size_t>(cu + cols * cv);
		nearest[c] = std::min(nearest[c], z);
		count[c]++;
	}
	std::vector<TPointId> sortedFound = found;
	std::sort(sortedFound.begin(), sortedFound.end());
	const mrpt::poses::CPose3D Tcw = -f.pose;
	for (std::size_t j : inView)
	{
		const TPointId id = local.ids[j];
		if (std::binary_search(sortedFound.begin(), sortedFound.end(), id)) continue;
		const auto& P = local.positions[j];
		double x, y, z;
		Tcw.composePoint(P.x, P.y, P.z, x, y, z);
		if (z <= 0) continue;
		const double u = f.camera.fx() * x / z + f.camera.cx(), v = f.camera.fy() * y / z + f.camera.cy();
		const int cu = static_cast<int>(u) / kCell, cv = static_cast<int>(v) / kCell;
		if (u < 0 || v < 0 || cu >= cols || cv >= rows) continue;
		// Keypoints are sparse (about one per cell): the 3 x 3 cells around it. Two or more surfaces
		// measured there, all well behind the point (3 sigma of the depth noise, at least 20 cm): the
		// space it should fill is empty. A nearer surface would only hide it (occlusion is no
		// evidence), and one in the neighbourhood vetoes, so depth edges stay conservative.
		float near = std::numeric_limits<float>::infinity();
		int n = 0;
		for (int dv = -1; dv <= 1; dv++)
			for (int du = -1; du <= 1; du++)
			{
				const int a = cu + du, b = cv + dv;
				if (a < 0 || b < 0 || a >= cols || b >= rows) continue;
				const auto c = static_cast<std::size_t>(a + cols * b);
				near = std::min(near, nearest[c]);
				n += count[c];
			}
		if (n >= 2 && near > z + std::max(0.2, 3 * noise_.sigma(z))) out.push_back(id);
	}
	return out;
}

void CTracker::ageMovers()
{
	// Kept a few frames after the check last saw the mover move (the masker's holdFrames idea):
	// its keypoints are uncertain meanwhile, so they are not in the groups the check tests.
	constexpr int kHoldFrames = 5;
	std::vector<CGeometricDynamicCheck::TMoverRegion> next;
	for (auto r : movers_)
		if (++r.age <= kHoldFrames) next.push_back(r);
	movers_ = std::move(next);
}

void CTracker::updateMovers(TFrame& f, const std::vector<std::size_t>& moving)
{
	ageMovers();
	moversFrame_ = f.id;
	for (const auto& r : check_.moverRegions(f.features, moving)) movers_.push_back(r);
	check_.markMovers(f.features, movers_);
}

bool CTracker::relocalise(TFrame& f, TResult& r)
{
	std::vector<TKeyFrameId> order;
	if (vocabulary_ && database_ && database_->size() > 0)
	{
		// The keyframes that look like the frame, best covisibility group first (ORB-SLAM2).
		const auto bow = vocabulary_->bowOf(f.features);
		for (const auto& c : groupCandidates(database_->query(bow->words), map_))
			if (opts_.relocKeyFrames == 0 || order.size() < opts_.relocKeyFrames) order.push_back(c.keyFrame);
	}
	else
	{
		// Newest first: after a short loss the camera is most likely where it just was.
		const std::vector<TKeyFrameId> ids = map_.keyFrameIds();
		const std::size_t n = ids.size();
		const std::size_t first = opts_.relocKeyFrames == 0 || n <= opts_.relocKeyFrames ? 0 : n - opts_.relocKeyFrames;
		for (std::size_t j = n; j-- > first;) order.push_back(ids[j]);
	}
	for (const TKeyFrameId k : order)
	{
		const TLocalMapPoints pts = map_.keyFramePoints(k);
		const auto m = matcher_.matchBruteForce(f, pts.descriptors);
		if (m.size() < 15) continue;
		const auto obs = makePoseObservations(f, m, pts, scaleFactor_, noise_);
		const TPoseEstimate pnp = optimizer_.solvePnPRansac(obs, f.camera);
		if (!pnp.ok) continue;
		const auto prevRef = refKf_;
		refKf_ = k;
		if (trackLocalMap(f, pnp.cameraInWorld, {}, r, opts_.localRadius, true))
		{
			r.relocalised = true;
			return true;
		}
		refKf_ = prevRef;
	}
	return false;
}

CTracker::TResult CTracker::track(TFrame& f)
{
	const mrpt::poses::CPose3D lastPose = lastFramePose();
	if (hook_) hook_();  // test only: where a correction racing tracking would land
	const TResult r = trackFrom(f, lastPose);
	if (r.relocalised) relocalisedFrame_ = f.id;
	anchor(f, lastPose);
	return r;
}

bool CTracker::plausible(const mrpt::poses::CPose3D& pose, std::size_t inliers, TResult& r, bool relocalising) const
{
	// A relocalisation is never held more than tracking's own solutions.
	const std::size_t strong =
		relocalising && opts_.relocInliers > 0 ? std::min(opts_.weakInliers, opts_.relocInliers) : opts_.weakInliers;
	if (!prior_ || strong == 0 || inliers >= strong) return true;
	const mrpt::poses::CPose3D d = pose - *prior_;
	const double angleDeg = mrpt::poses::Lie::SO<3>::log(d.getRotationMatrix()).norm() * 180.0 / M_PI;
	if (d.norm() <= opts_.priorDeparture * priorScale_ && angleDeg <= opts_.priorDepartureDeg * priorScale_)
		return true;
	r.implausible = true;
	return false;
}

std::size_t CTracker::stepThreeEvidence(const TFrame& f, const std::vector<TMatch>& used, const TLocalMapPoints& pts,
										const TPoseEstimate& e, std::size_t mapInliers) const
{
	// One or two map points agreeing by chance say nothing: at least half what a frame is tracked on.
	if (2 * mapInliers < opts_.minTrackedInliers) return mapInliers;
	std::size_t mapMatched = 0, certain = 0;
	for (std::size_t k = 0; k < used.size(); k++)
	{
		if (pts.ids[used[k].point] >= 0) mapMatched++;
		if (e.inlier[k] && !e.isMoving(k) && !f.features.isUncertain(used[k].keypoint)) certain++;
	}
	return mapMatched > 0 && 2 * mapInliers >= mapMatched ? std::max(certain, mapInliers) : mapInliers;
}

CTracker::TResult CTracker::trackFrom(TFrame& f, const mrpt::poses::CPose3D& lastPose)
{
	TResult r;
	f.tracked = false;
	f.numInliers = 0;
	f.mapPoints.assign(f.size(), -1);
	mrpt::poses::CPose3D predicted = velocity_ ? lastPose + *velocity_ : lastPose;
	const double sinceLast =
		last_ && f.timestamp > last_->timestamp ? intervalsIn(f.timestamp - last_->timestamp, frameInterval_) : 1.0;
	// Over the frame intervals since the last frame, against those the last step took: live input
	// and the TUM recordings drop frames (fr3 sequences: steps of two and three intervals), and a
	// frame after three dropped ones was predicted a step away from the last frame where the camera
	// had moved four (a fast turn then leaves the search radius: found again only by brute force).
	// A coasted velocity (lost frames) is per frame as it is.
	if (velocity_ && lostRun_ == 0 && last_ && last_->tracked && f.timestamp > last_->timestamp &&
		velocityInterval_ > 0)
	{
		const double then = intervalsIn(velocityInterval_, frameInterval_);
		if (sinceLast != then)
			predicted = lastPose + scaledTwist(mrpt::poses::Lie::SE<3>::log(*velocity_), sinceLast / then);
	}
	f.pose = predicted;
	// A prediction from measured motion (the last frame tracked, not coasting) is evidence a weak solution must agree
	// with; after a loss the coasted one stands for priorLostFrames frames, wider each: a person who blinded the camera
	// stays and fills the first frames back. A refused frame is lost too, so the next is checked as well.
	// The departures allowed grow with the frames since the motion was last measured: each lost
	// frame, and each interval since the last frame (dropped ones), the camera may have sped up.
	prior_.reset();
	priorScale_ = 1;
	if (velocity_ &&
		((lostRun_ == 0 && last_ && last_->tracked) || (lostRun_ > 0 && lostRun_ <= opts_.priorLostFrames)))
	{
		prior_ = predicted;
		priorScale_ = (1.0 + static_cast<double>(lostRun_)) * sinceLast;
	}
	motionPrior_.reset();
	if (!refKf_)
	{
		// A loaded map (map reuse): the first frames are placed in it by relocalisation.
		if (map_.numKeyFrames() > 0 && relocalise(f, r))
		{
			f.tracked = true;
			r.ok = true;
		}
		return r;
	}
	check_.markMovers(f.features, movers_);
	// The mean step of the last tracked frames (not the last step alone, whose noise a prior would
	// pass on), taken as many times as this frame's interval holds the sensor's frame interval: a dropped
	// frame does not leave the prior a step behind, and a stamp a microsecond off (a recording
	// played through OpenNI2) changes nothing. Once lostVelocityFrames steps were measured since a
	// loss or a relocalisation (ORB-SLAM2 skips its motion model for two frames after one).
	if (opts_.motionPriorSigma > 0 && opts_.motionPriorSigmaDeg > 0 && lostRun_ == 0 && last_ && last_->tracked &&
		f.timestamp > last_->timestamp && smoothMotions_ >= opts_.lostVelocityFrames && !recentMotion_.empty())
	{
		motionPrior_ = CPoseOptimizer::TPosePrior{lastPose + scaledTwist(meanRecentMotion(), sinceLast),
												  opts_.motionPriorSigma, opts_.motionPriorSigmaDeg * M_PI / 180.0};
	}

	// 1. Motion model against the last frame's points (map points and temporary depth points).
	std::optional<mrpt::poses::CPose3D> guess;
	TLocalMapPoints pts;
	std::vector<TMatch> used;
	TPoseEstimate e;
	if (last_ && last_->tracked)
	{
		pts = lastFramePoints(lastPose);
		used = matcher_.searchByProjection(f, predicted, pts, opts_.motionRadius, nullptr, false, scaleFactor_);
		if (used.size() < 2 * opts_.minTrackedInliers)  // a poor prediction (sudden motion): search wider
			used = matcher_.searchByProjection(f, predicted, pts, 2 * opts_.motionRadius, nullptr, false, scaleFactor_);
		r.motionMatches = used.size();
		e = refineWith(f, used, pts, predicted);
		if (!e.ok)
		{
			// The prediction was too far off for projection search: match by descriptor, PnP.
			used = matcher_.matchBruteForce(f, pts.descriptors);
			const auto obs = makePoseObservations(f, used, pts, scaleFactor_, noise_);
			const TPoseEstimate pnp = optimizer_.solvePnPRansac(obs, f.camera);
			motionPrior_.reset();  // the prediction was too far off to search around
			if (pnp.ok)
			{
				e = refineWith(f, used, pts, pnp.cameraInWorld);
				r.recoveredByPnP = e.ok;
			}
		}
		if (e.ok) guess = e.cameraInWorld;
	}
	std::vector<TPointId> seeds;
	if (guess)
		for (std::size_t k = 0; k < used.size(); k++)
			if (e.inlier[k] && pts.ids[used[k].point] >= 0) seeds.push_back(pts.ids[used[k].point]);
	// 2. The local map, from the motion-model pose, or the prediction when there is none (the last frame was lost: the
	// pose coasted, unmeasured). Around such a prediction the search is as wide as the motion model's (ORB-SLAM2
	// searches coarser after a relocalisation): the narrow radius left the first frame back on fr1 too few matches.
	const bool okLocal =
		trackLocalMap(f, guess ? *guess : predicted, seeds, r, guess ? opts_.localRadius : opts_.motionRadius);
	if (okLocal)
	{
		f.tracked = true;
		r.ok = true;
		return r;
	}
	// 3. The local map did not confirm it (the view has left the mapped part faster than keyframes
	// came): keep the last-frame pose when it had enough support; the new keyframe that the system
	// then inserts restores the map around it. Its evidence against the motion model is all its
	// certain inliers (none near a detection or a mover) when the map points it matched mostly
	// agree, else those map points alone: a person moving beside the camera, whom no detector
	// reported, fills the last frame with temporary depth points that agree with each other on the
	// person's motion, and the map's points are the outliers of that solution.
	if (guess && e.numInliers >= opts_.minTrackedInliers &&
		plausible(*guess, stepThreeEvidence(f, used, pts, e, seeds.size()), r))
	{
		f.pose = *guess;
		f.tracked = true;
		f.numInliers = e.numInliers;
		for (std::size_t k = 0; k < used.size(); k++)
			if (e.inlier[k] && pts.ids[used[k].point] >= 0) f.mapPoints[used[k].keypoint] = pts.ids[used[k].point];
		r.inliers = e.numInliers;
		r.ok = true;
		return r;
	}
	motionPrior_.reset();
	if (relocalise(f, r))
	{
		f.tracked = true;
		r.ok = true;
		return r;
	}
	// Lost: the first lost frame already coasts on the mean motion (see meanRecentMotion); a
	// refused solution is no pose to keep.
	TResult scratch;
	if (guess && plausible(*guess, stepThreeEvidence(f, used, pts, e, seeds.size()), scratch))
		f.pose = *guess;
	else if (lostRun_ == 0 && !recentMotion_.empty())
		f.pose = lastPose + scaledTwist(meanRecentMotion(), sinceLast);
	else
		f.pose = predicted;
	return r;
}
}  // namespace mrpt_yesslam
