#pragma once
// Frame-to-map tracking (paper section 2.2, as ORB-SLAM2's Tracking): a constant-velocity motion
// model predicts the pose; the last frame's points (its map points, plus temporary points from its
// depth, as ORB-SLAM2's RGB-D "visual odometry" points) are matched by projection and the pose is
// refined (eq. 7); then the local map (the reference keyframe and its covisible keyframes) is
// searched by projection and the pose refined again on map points only. PnP + RANSAC recovers when
// the prediction fails; when everything fails, the frame is relocalised against the keyframes.
// Only static features (outside the dynamic mask, eq. 3) are ever matched.
//
// Tracking keeps no copy of map state: the last frame's pose is re-derived for every prediction
// from its reference keyframe's current pose (ORB-SLAM2's UpdateLastFrame), so that a map corrected
// by local BA (and later loop closing) does not make the camera jump; a reference keyframe erased
// by keyframe culling is replaced by its nearest good ancestor in the spanning tree.
#include <mrpt/config/CLoadableOptions.h>
#include <mrpt/math/CVectorFixed.h>

#include <memory>
#include <deque>
#include <functional>
#include <optional>
#include <string>

#include "mrpt_yesslam/data/CSparseMap.h"
#include "mrpt_yesslam/data/TAnchor.h"
#include "mrpt_yesslam/dynamic/CGeometricDynamicCheck.h"
#include "mrpt_yesslam/feature/COrbMatcher.h"
#include "mrpt_yesslam/place/CBowDatabase.h"
#include "mrpt_yesslam/place/CVocabulary.h"
#include "mrpt_yesslam/geometry/CPoseOptimizer.h"
#include "mrpt_yesslam/geometry/DepthNoise.h"
#include "mrpt_yesslam/util/OptionTable.h"

namespace mrpt_yesslam
{
/** Tracks frames against a CSparseMap. */
class CTracker
{
   public:
	/** Section [Tracking]: the pose optimiser's keys plus these. */
	struct TOptions : public TTableOptions<TOptions>
	{
		CPoseOptimizer::TOptions pose;
		/** Keypoints farther than this are not used, m. Far depth is already weighted down by the
		 * noise model (TDepthNoise, k z^2.5, in pose and BA), and far keypoints still pin the rotation
		 * (ORB-SLAM2 keeps its far points too): a 4 m cut lost the far wall whenever people filled
		 * the near view (default config 1.5x sim.ini's ATE on unseen walking sequences; 6 m: equal).
		 * The limit only drops the Kinect's unreliable fringe beyond its range. */
		double maxDepth = 6.0;
		double motionRadius = 15;  //!< pixel search radius around motion-model projections (ORB-SLAM2: 15)
		double localRadius = 4;    //!< pixel search radius for the local map
		/** Local-map search as ORB-SLAM2's: a map point is in view only within its pyramid's
		 * distance range and 60 degrees of its mean viewing direction, and is searched at the
		 * pyramid level its distance predicts (COrbMatcher::searchByProjection). */
		bool viewChecks = true;
		int maxHamming = 100;             //!< ORB-SLAM2's TH_HIGH
		double ratio = 0.9;               //!< nearest/second-nearest ratio for projection search (ORB-SLAM2: 0.9)
		std::size_t localKeyFrames = 40;  //!< most keyframes in the local map (ORB-SLAM2: 80)
		std::size_t localNeighbours =
			10;  //!< best covisible keyframes added around each keyframe that sees the frame's matches
		std::size_t minTrackedInliers = 20;  //!< fewer inliers after the local map: tracking failed
		/** No pose without evidence (issue 39): a solution on fewer inliers than this must agree
		 * with the motion model's prediction (made from tracked frames) within priorDeparture and
		 * priorDepartureDeg, or the frame is not tracked (it coasts). A hand-held camera does not
		 * move 20 cm off its course in 33 ms; a few inliers on a person who moves with the camera
		 * (or on a mis-masked one) can make a pose that does. 0 = off. */
		std::size_t weakInliers = 80;
		/** m and degrees: the farthest a weak solution may lie and turn from the prediction, per
		 * frame interval since the last frame (dropped frames widen them; see priorLostFrames). */
		double priorDeparture = 0.05;
		double priorDepartureDeg = 5;
		/** A relocalisation on at least this many inliers is a pose of its own: it is held to the
		 * prediction tracking failed to confirm only below it (ORB-SLAM2 takes one on 50; 0 = held
		 * as any other solution). */
		std::size_t relocInliers = 50;
		/** After a loss (a person filled the view, or a weak solution was refused) the coasted
		 * prediction still judges weak solutions for this many lost frames, counted since the
		 * motion was last measured, with 1 + n times the departures: the first frames back are the
		 * ones a person still covers. Never beyond lostCoastFrames (the prediction is held then,
		 * and with lostDamping 0 at once). 0 = only a prediction from tracked frames judges, none
		 * after any loss (a refused frame's successor included). */
		std::size_t priorLostFrames = 3;
		/** The motion model's prediction (the mean step of the last lostVelocityFrames tracked
		 * frames, times the frame intervals since the last, once that many steps were measured since a loss or a
		 * relocalisation) as a weak term of the pose solve, sigma per camera axis (either 0 = no
		 * prior): far points leave a sideways shift and a turn that cancel in the image nearly
		 * free, and without it the pose zig-zags along that pair frame to frame. */
		double motionPriorSigma = 0.005;  //!< m
		double motionPriorSigmaDeg = 1;   //!< degrees
		/** Relocalisation tries at most this many keyframes: the best place-recognition candidates
		 * (with a vocabulary), else the newest keyframes (0 = all). */
		std::size_t relocKeyFrames = 60;
		std::size_t lostCoastFrames = 30;  //!< lost frames that still continue the last velocity
		double lostDamping = 0.9;          //!< per lost frame, the velocity is scaled by this (0 = hold at once)
		/** Lost frames continue the mean motion of this many last tracked frames (1: the last one). */
		std::size_t lostVelocityFrames = 3;
		/** A map point behind which farther surfaces are measured in this many consecutive tracked
		 * frames has moved away and is erased (0 = never). */
		int seeThroughFrames = 3;
		/** Where the depth image was taken at another moment than the colour image (TUM folders:
		 * depth.txt's stamps), each keypoint's depth is moved to the colour image's moment with the
		 * motion model's velocity (feature/DepthMoment.h). */
		bool depthMoment = false;
		/** The colour camera's rolling-shutter readout, seconds from its first row to its last:
		 * keypoints are moved to the middle row's moment with the motion model's velocity
		 * (feature/RollingShutter.h); 0 = global shutter; -1 = auto, which yesslam resolves from
		 * its input (SlamJob: a yesslam-sim sequence's own, else the camera's, TRgbdCamera::readout,
		 * else 0); a system used directly takes -1 as 0. */
		double rollingShutter = -1;

		/** Every option once: key, member, range, help (load, dump and keys come from it). */
		COptionTable table();
	};

	/** How one frame went. */
	struct TResult
	{
		bool ok = false;
		bool relocalised = false;
		bool recoveredByPnP = false;  //!< the motion model failed, PnP on the last frame's points worked
		std::size_t motionMatches = 0, localMatches = 0, inliers = 0;
		/** A weak solution far from the motion model's prediction was refused (weakInliers). */
		bool implausible = false;
		/** Map points erased as moving: in a group the geometric check found moving, or seen through. */
		std::size_t movingPointsErased = 0;
	};

	/** `scaleFactor`: the ORB pyramid's ([ORB] scaleFactor): search windows and observation sigmas
	 * scale with it; `depthNoise`: the sensor's ([Camera]), for the pose solve's depth term and the
	 * see-through test. */
	CTracker(const TOptions& opts, CSparseMap& map, double scaleFactor = 1.2,
			 const CGeometricDynamicCheck::TOptions& check = CGeometricDynamicCheck::TOptions(),
			 const TDepthNoise& depthNoise = TDepthNoise());

	/** Tracks `f` (features filled in): sets pose, tracked, mapPoints and numInliers. Never throws
	 * for hard frames: when lost, the pose is the motion model's guess and tracked is false. */
	TResult track(TFrame& f);
	/** Makes keyframe `kf` the reference (a new keyframe); tracking then moves it to the keyframe
	 * sharing most points with each frame. When `kf` was made from the frame tracked last
	 * (`fromFrame` is its id), that frame is anchored to it (relative pose identity), as ORB-SLAM2
	 * records a new keyframe's frame relative to it. */
	void setReferenceKeyFrame(TKeyFrameId kf, std::optional<std::size_t> fromFrame = std::nullopt);
	/** The anchor of the frame track() saw last, taken right after its pose was computed (the
	 * keyframe's pose read then, not after a later mapping step moved it); none for another frame. */
	std::optional<TAnchor> anchorOf(std::size_t frameId) const;
	/** The reference keyframe: the one sharing most points with the last tracked frame (or the newest
	 * keyframe), or its nearest good ancestor once it was erased. */
	std::optional<TKeyFrameId> referenceKeyFrame() const;
	/** The frame tracking saw last, for the next prediction; its pose is kept relative to the
	 * reference keyframe at this moment. */
	void setLastFrame(const std::shared_ptr<const TFrame>& f);
	/** The camera's motion over the next `seconds` at the mean velocity of the last tracked frames
	 * ([Tracking] lostVelocityFrames of them): the pose of the camera then in the camera's frame
	 * now; none without a velocity (the start, or lost). */
	std::optional<mrpt::poses::CPose3D> motionOver(double seconds) const;
	/** Where the mover check found motion lately (image regions, kept a few frames): keypoints there
	 * are uncertain. */
	const std::vector<CGeometricDynamicCheck::TMoverRegion>& moverRegions() const { return movers_; }
	/** Test only: `hook` runs in track() after the last frame's pose was read, before matching. */
	void setHook(std::function<void()> hook) { hook_ = std::move(hook); }
	/** Relocalisation by place recognition (ORB-SLAM2's: BoW candidates of the keyframe database,
	 * grouped by covisibility, then PnP RANSAC) instead of trying the newest keyframes. */
	void setPlaceRecognition(std::shared_ptr<const CVocabulary> vocabulary,
							 std::shared_ptr<const CBowDatabase> database)
	{
		vocabulary_ = std::move(vocabulary);
		database_ = std::move(database);
	}
	/** Localisation only (a robot in a saved map): tracking never changes the map (no tracking
	 * statistics, no points erased as moving or seen through). */
	void setMapReadOnly(bool readOnly) { readOnly_ = readOnly; }
	const TOptions& options() const { return opts_; }

   private:
	/** track() with the last frame's pose (`lastPose`) read once from the map. */
	TResult trackFrom(TFrame& f, const mrpt::poses::CPose3D& lastPose);
	/** Records `f`'s anchor (its reference keyframe's pose read now) and the pose its prediction came from. */
	void anchor(const TFrame& f, const mrpt::poses::CPose3D& base);
	/** Pose from matched observations; refines from `guess`. */
	TPoseEstimate refineWith(const TFrame& f, const std::vector<TMatch>& m, const TLocalMapPoints& pts,
							 const mrpt::poses::CPose3D& guess) const;
	/** The last frame's map points and temporary depth points, placed with `lastPose`. */
	TLocalMapPoints lastFramePoints(const mrpt::poses::CPose3D& lastPose) const;
	/** The last tracked frames' mean motion over one frame interval (SE(3) log): what a lost frame coasts on. */
	mrpt::math::CVectorFixedDouble<6> meanRecentMotion() const;
	/** The sensor's frame interval as the last tracked steps measured it (their median); 0 if unknown. */
	double measuredFrameInterval() const;
	/** How many whole frame intervals of `typical` seconds `seconds` holds (at least 1; 1 if unknown). */
	static double intervalsIn(double seconds, double typical);
	/** The last frame's pose from its reference keyframe's current pose. */
	mrpt::poses::CPose3D lastFramePose() const;
	bool relocalise(TFrame& f, TResult& r);
	/** Whether a solution on `inliers` may be taken (see TOptions::weakInliers; a relocalisation's
	 * also TOptions::relocInliers); notes a refusal in `r`. */
	bool plausible(const mrpt::poses::CPose3D& pose, std::size_t inliers, TResult& r, bool relocalising = false) const;
	/** The prediction of the frame being tracked that weak solutions must agree with: made from
	 * tracked frames, or coasted over at most priorLostFrames lost ones; none without a velocity. */
	std::optional<mrpt::poses::CPose3D> prior_;
	/** The weak term refineWith adds to the pose solve (motionPriorSigma); none outside tracking's
	 * own searches (PnP recovery, relocalisation). */
	std::optional<CPoseOptimizer::TPosePrior> motionPrior_;
	double priorScale_ = 1;  //!< the departures allowed, times this: wider for each lost frame and each frame interval
							 //!< since the last frame
	/** Local map points in view but not found whose place `f` sees through (farther keypoints
	 * measured all around where the point should be in front). */
	std::vector<TPointId> seenThrough(const TFrame& f, const TLocalMapPoints& local,
									  const std::vector<std::size_t>& inView, const std::vector<TPointId>& found) const;
	/** The inliers that count as evidence for step 3's solution `e` against the last frame's points
	 * (`used` matches of `pts`): its certain ones, when at least half the map points it matched
	 * are among its `mapInliers` and those are at least half of minTrackedInliers; else those alone. */
	std::size_t stepThreeEvidence(const TFrame& f, const std::vector<TMatch>& used, const TLocalMapPoints& pts,
								  const TPoseEstimate& e, std::size_t mapInliers) const;
	/** Ages the mover regions, adds those of `moving` (keypoints of f) and marks f's keypoints in them. */
	void updateMovers(TFrame& f, const std::vector<std::size_t>& moving);
	/** One frame older: drops the regions the check has not seen move for a few frames. */
	void ageMovers();
	/** Matches the local map around the keyframes that see `seeds` (the points the frame already
	 * matched; none: around the reference keyframe), searching `radius` pixels around each
	 * projection from `guess`, and refines; on success fills the frame and the keyframe sharing
	 * most points becomes the reference. */
	bool trackLocalMap(TFrame& f, const mrpt::poses::CPose3D& guess, const std::vector<TPointId>& seeds, TResult& r,
					   double radius, bool relocalising = false);

	TOptions opts_;
	CSparseMap& map_;
	CPoseOptimizer optimizer_;
	CGeometricDynamicCheck check_;
	COrbMatcher matcher_;
	double scaleFactor_;
	TDepthNoise noise_;  //!< the sensor's depth noise ([Camera])
	std::shared_ptr<const TFrame> last_;
	TAnchor lastAnchor_;  //!< where the last frame hangs in the map (its reference keyframe, T_ref_last)
	/** What track() left for setLastFrame and anchorOf: the frame's id, its anchor, and the last
	 * frame's pose its prediction started from (the velocity is measured against that one, in the
	 * same state of the map as the new pose). */
	struct TTracked
	{
		std::size_t frameId = 0;
		TAnchor anchor;
		mrpt::poses::CPose3D base;
		std::uint64_t generation = 0;  //!< the map's correction generation when the anchor was taken
	};
	std::optional<TTracked> tracked_;
	std::optional<mrpt::poses::CPose3D> velocity_;  //!< last motion, T_{k-1,k}
	double velocityInterval_ = 0;                   //!< seconds between the two frames of velocity_
	/** One tracked frame's motion from the frame before it: SE(3) log and the seconds it took. */
	struct TMotion
	{
		mrpt::math::CVectorFixedDouble<6> twist;
		double seconds = 0;
	};
	/** Motions of the last tracked frames, oldest first (lostVelocityFrames of them); emptied when
	 * tracking is lost, so that motions from before a loss never mix with those after it. */
	std::deque<TMotion> recentMotion_;
	double frameInterval_ = 0;  //!< measuredFrameInterval(), kept by setLastFrame (the only place the motions change)
	/** Steps measured since the last loss or relocalisation (the motion prior needs
	 * lostVelocityFrames of them). */
	std::size_t smoothMotions_ = 0;
	std::optional<std::size_t> relocalisedFrame_;  //!< the last frame relocalisation placed
	std::size_t lostRun_ = 0;  //!< lost frames since the motion was last measured (two tracked frames in a row)
	std::optional<TKeyFrameId> refKf_;
	/** Movers the geometric check found in recent frames (their keypoints start uncertain). */
	std::vector<CGeometricDynamicCheck::TMoverRegion> movers_;
	std::optional<std::size_t> moversFrame_;  //!< the frame updateMovers aged the regions for last
	std::shared_ptr<const CVocabulary> vocabulary_;
	std::shared_ptr<const CBowDatabase> database_;
	bool readOnly_ = false;       //!< see setMapReadOnly
	std::function<void()> hook_;  //!< see setHook
};

/** Observations for the pose optimiser from matches (sigma = scale factor ^ octave; where
 * `depthNoise` is used, the keypoint's depth too, with its level-0 sigma: see CTracker.cpp; a depth
 * beyond its farDepth is kept but carries no residual, sigmaZ 0). */
std::vector<TPoseObservation> makePoseObservations(const TFrame& f, const std::vector<TMatch>& m,
												   const TLocalMapPoints& pts, double scaleFactor,
												   const TDepthNoise& depthNoise = TDepthNoise::none());
}  // namespace mrpt_yesslam
