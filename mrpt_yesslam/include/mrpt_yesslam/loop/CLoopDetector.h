#pragma once
// Loop detection (paper section 2.4, eq. 18-23, with ORB-SLAM2's LoopClosing::DetectLoop and
// ComputeSim3 where the paper is silent). For each new keyframe:
// 1. candidates: keyframes of the database sharing words with it, except those covisible with it
//    (N_cov > 15 shared points, and any direct neighbour, as ORB-SLAM2); each scored with
//    S_Loop = alpha s_BoW + (1 - alpha) S_G (eq. 19), alpha = 0.45 when the keyframe holds at least
//    five semantic objects, else 0.65 (eq. 20); a candidate must score at least the lowest S_Loop of
//    the keyframe's own covisible keyframes (ORB-SLAM2's minScore), and covisibility groups keep the
//    best keyframe of each group scoring >= 0.75 of the best group; keyframes younger than
//    minLoopAge seconds are not candidates (as stella_vslam's minimum distance on the graph);
// 2. consistency (eq. 21-22): a candidate's group (it and its covisible keyframes) must overlap a
//    group of the previous keyframe's candidates in N_c >= 3 consecutive keyframes;
// 3. geometric verification: keypoints matched through the vocabulary's direct index, then a rigid
//    transform by RANSAC on their 3D points (eq. 23 with s = 1: RGB-D measures scale, so ORB-SLAM2's
//    Sim3 becomes SE3; inliers judged by reprojection in both keyframes, ORB-SLAM2's Sim3Solver
//    test), refined on the inliers; finally the map points of the candidate's group, projected with
//    the corrected pose, must match enough keypoints (ORB-SLAM2: 40).
// S_G uses the static semantic objects only: a person says nothing about where the camera is.
#include <mrpt/poses/CPose3D.h>

#include <deque>
#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <set>
#include <utility>
#include <vector>

#include "mrpt_yesslam/geometry/DepthNoise.h"
#include "mrpt_yesslam/data/CSparseMap.h"
#include "mrpt_yesslam/keyframes/CSemanticKeyFrameSelector.h"
#include "mrpt_yesslam/place/CBowDatabase.h"
#include "mrpt_yesslam/place/CVocabulary.h"
#include "mrpt_yesslam/util/OptionTable.h"

namespace mrpt_yesslam
{
/** A verified loop: keyframe `current` sees again the place of keyframe `matched`. */
struct TLoop
{
	TKeyFrameId current = 0, matched = 0;
	double score = 0;  //!< S_Loop of the pair
	/** Pose of the current camera in the matched one's frame, T_matched_current (from RANSAC). */
	mrpt::poses::CPose3D relative;
	/** T_w_current that makes the current keyframe agree with the matched place. */
	mrpt::poses::CPose3D correctedPose;
	std::size_t ransacInliers = 0;
	/** Keypoint of the current keyframe -> map point of the matched place (loop fusion). */
	std::vector<std::pair<std::size_t, TPointId>> pointMatches;
};

/** One keyframe that appearance found for a loop query, and where it stopped (loop_candidates.csv):
 * so that every candidate can be labelled by a ground truth (bench/bench_loop_real.sh). */
struct TLoopCandidate
{
	TKeyFrameId query = 0, candidate = 0;
	double queryStamp = 0, candidateStamp = 0;  //!< seconds, as in the trajectories
	double bowScore = 0;                        //!< the vocabulary's score of the pair
	double loopScore = 0;                       //!< S_Loop (eq. 19); 0 where it was not needed (covisible, young)
	double minScore = 0;  //!< the bar S_Loop had to clear: the lowest of the query's covisible keyframes
	/** covisible (excluded: the map links them), young (minLoopAge), below_min_score (eq. 19 with
	 * the semantic blend), not_group_best (its covisibility group chose another, or scored under
	 * 0.75 of the best), inconsistent (eq. 21-22), then verification's: gone (culled meanwhile),
	 * few_matches, ransac (too few inliers of the rigid fit), pose_solve (the reprojection solve),
	 * projection (too few of the place's points found), accepted; untried (another was accepted);
	 * dropped (accepted, but its keyframes were gone before the correction, which moved nothing). */
	const char* stage = "";
	std::size_t matches = 0, inliers = 0;  //!< verification's keypoint matches and inliers where it got that far
};

/** Counts of loop detection (stats.json). */
struct TLoopDetectionStats
{
	std::size_t queries = 0;           //!< keyframes looked up
	std::size_t consistent = 0;        //!< candidates that passed the consistency test (detected)
	std::size_t accepted = 0;          //!< passed geometric verification
	std::size_t rejectedGeometry = 0;  //!< detected, refused by the geometry
};

/** Finds loop candidates for new keyframes and verifies them. Not thread-safe: one caller. */
class CLoopDetector
{
   public:
	/** Section [LoopClosing]. */
	struct TOptions : public TTableOptions<TOptions>
	{
		bool enabled = true;          //!< detect and close loops (the command line's --no-loop-closure sets false)
		std::string vocabulary;       //!< vocabulary file; empty = the shipped one
		int directLevel = 2;          //!< depth of the direct index's nodes (ORB-SLAM2: 2 of 6 levels)
		int covisibleWeight = 15;     //!< N_cov: keyframes sharing more points are covisible, never candidates
		double alphaRich = 0.45;      //!< eq. 20: alpha with at least `richObjects` semantic objects ...
		double alphaPoor = 0.65;      //!< ... and with fewer
		std::size_t richObjects = 5;  //!< N_sw threshold of eq. 20
		/** Eq. 19 adds a BoW score (0.01-0.1 between different views) to S_G (0-1): the semantic term
		 * then decides alone. With this, s_BoW is first divided by the query's best score with its
		 * covisible keyframes (capped at 1), DBoW2's normalised similarity (Galvez-Lopez and Tardos
		 * 2012), so both terms span [0, 1]. */
		bool normaliseBow = true;
		std::size_t consistency = 3;  //!< N_c: consecutive keyframes whose candidate groups overlap
		/** Candidates must be at least this many seconds older than the keyframe: keyframes of a few
		 * seconds ago that no longer share points look alike by chance or are the place tracking
		 * just left, not a loop (stella_vslam excludes them by distance in the graph). */
		double minLoopAge = 5;
		std::size_t minKeyFrames = 10;  //!< no detection before the map has this many keyframes (ORB-SLAM2)
		/** How a pair's keypoints are first matched: "all" (every static keypoint with depth
		 * against every other) or "bow" (within the direct index's nodes, ORB-SLAM2's SearchByBoW). */
		std::string matching = "all";
		int maxHamming = 50;                 //!< direct-index matching (ORB-SLAM2's TH_LOW)
		double ratio = 0.75;                 //!< nearest / second nearest (ORB-SLAM2's loop matching)
		std::size_t minMatches = 20;         //!< direct-index matches needed to try RANSAC (ORB-SLAM2: 20)
		std::size_t minInliers = 20;         //!< RANSAC inliers needed (ORB-SLAM2: 20)
		std::size_t ransacIterations = 300;  //!< ORB-SLAM2's Sim3 RANSAC
		/** RANSAC inliers that let guided matching look for the rest (then minInliers must agree). */
		std::size_t minSeedInliers = 12;
		/** Guided matching's search radius, pixels at level 0 (ORB-SLAM2's SearchBySim3: 7.5; 0 = none). */
		double guidedRadius = 7.5;
		int guidedHamming = 100;  //!< guided matching's descriptor distance (ORB-SLAM2's TH_HIGH)
		std::size_t minProjectionMatches =
			40;                        //!< matches of the group's points with the corrected pose (ORB-SLAM2: 40)
		double projectionRadius = 10;  //!< pixels at level 0 for that search (ORB-SLAM2: 10)

		/** Every option once: key, member, range, help (load, dump and keys come from it). */
		COptionTable table();
	};

	/** `semantic`: the [KeyFrames] options whose grid and gamma define S_G (eq. 9-10);
	 * `scaleFactor`: the ORB pyramid's; `maxDepth`: tracking's; `depthNoise`: the sensor's
	 * ([Camera]): the relative pose's final solve weighs depth with it beside the reprojection
	 * (0: reprojection alone). */
	CLoopDetector(const TOptions& opts, const CSparseMap& map, std::shared_ptr<const CVocabulary> vocabulary,
				  std::shared_ptr<const CBowDatabase> database, const CSemanticKeyFrameSelector::TOptions& semantic,
				  double scaleFactor = 1.2, double maxDepth = 6.0, const TDepthNoise& depthNoise = TDepthNoise());

	/** Looks for a loop closed by keyframe `kf` (its words in the database already). */
	std::optional<TLoop> detect(TKeyFrameId kf);
	/** S_Loop (eq. 19) of keyframe `a` (the query) and `b`, with their words; `reference`: a's
	 * referenceScore() when known (computed otherwise; only used with normaliseBow). */
	double loopScore(const CKeyFrame& a, const CKeyFrame& b, double reference = -1) const;
	/** Eq. 20's alpha for keyframe `k`. */
	double alphaOf(const CKeyFrame& k) const;
	/** The best BoW score between `k` and its covisible keyframes (0 without any). */
	double referenceScore(const CKeyFrame& k) const;
	/** S_G (eq. 10) of two keyframes on their static detections. */
	double semanticSimilarity(const CKeyFrame& a, const CKeyFrame& b) const;
	/** Geometric verification of `kf` against `candidate` alone (no consistency test); `outcome`
	 * (optional) gets the stage it stopped at and its counts. */
	std::optional<TLoop> verify(TKeyFrameId kf, TKeyFrameId candidate, TLoopCandidate* outcome = nullptr) const;
	/** The candidates of the queries since the last call, oldest first (moved out). */
	std::vector<TLoopCandidate> takeCandidates() { return std::exchange(candidates_, {}); }
	const TLoopDetectionStats& stats() const { return stats_; }
	const TOptions& options() const { return opts_; }
	/** Keyframes with ids below `id` come from a loaded map (an earlier session): they are old
	 * enough for a loop whatever their timestamps say (another day's clock, or a recording that
	 * restarts its clock). */
	void setSessionStart(TKeyFrameId id) { sessionStart_ = id; }
	/** Test only: `hook` runs in verify() after the pair's measurements were fitted and before the
	 * place's map points are read: where a BA or a correction landing meanwhile moves the place. */
	void setVerifyHook(std::function<void()> hook) { verifyHook_ = std::move(hook); }

   private:
	/** verify(), its outcome written to the candidate's record (`recordOf`: candidate -> index in candidates_). */
	std::optional<TLoop> verifyRecorded(TKeyFrameId kf, TKeyFrameId candidate,
										const std::map<TKeyFrameId, std::size_t>& recordOf);
	std::function<void()> verifyHook_;  //!< setVerifyHook
	struct TGroup
	{
		std::set<TKeyFrameId> members;
		std::size_t consistency = 0;
	};

	TOptions opts_;
	const CSparseMap& map_;
	std::shared_ptr<const CVocabulary> vocabulary_;
	std::shared_ptr<const CBowDatabase> database_;
	CSemanticKeyFrameSelector::TOptions semantic_;
	double scaleFactor_, maxDepth_;
	TDepthNoise noise_;             //!< the sensor's depth noise ([Camera])
	std::vector<TGroup> groups_;    //!< candidate groups of the previous keyframe
	TKeyFrameId sessionStart_ = 0;  //!< see setSessionStart
	TLoopDetectionStats stats_;
	std::vector<TLoopCandidate> candidates_;  //!< see takeCandidates
};
}  // namespace mrpt_yesslam
