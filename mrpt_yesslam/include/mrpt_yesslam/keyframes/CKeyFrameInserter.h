#pragma once
// Decides which tracked frames become keyframes, by one of two policies ([KeyFrames] policy), so
// that both can be compared on the same run (the paper's figure 11):
// - semantic: the paper's Algorithm 1 (CSemanticKeyFrameSelector). The decision comes when an
//   interval closes and may name an earlier frame of it. Beyond the paper, a safety net that
//   ORB-SLAM2 also has (its condition c1c): when the inliers of the current frame fall below
//   `forceTrackedRatio` of the reference keyframe's points, the view is leaving the map and a
//   keyframe is inserted at once; without it a fast turn inside an interval loses tracking.
//   Such keyframes are counted separately ("forced") in stats.json. Also beyond the paper, which
//   inserts one keyframe per interval for ever: the frame Algorithm 1 chose becomes a keyframe only
//   if it sees something the map does not - it tracks fewer than `semanticRefRatio` of the
//   reference keyframe's points, or too few close points (ORB-SLAM2's condition c2). Without it a
//   camera that keeps revisiting a mapped room adds a keyframe every interval for ever.
// - orbslam: ORB-SLAM2's Tracking::NeedNewKeyFrame for RGB-D (c1a: maxFrames since the last
//   keyframe; c1b: minFrames passed; c1c: inliers < 25% of the reference's; c2: inliers < 75% of
//   the reference's or too few close points tracked, and more than 15 inliers).
#include <deque>
#include <optional>

#include "mrpt_yesslam/data/TFrame.h"
#include "mrpt_yesslam/keyframes/CSemanticKeyFrameSelector.h"
#include "mrpt_yesslam/util/OptionTable.h"

namespace mrpt_yesslam
{
/** The keyframe decision for a stream of tracked frames. */
class CKeyFrameInserter
{
   public:
	/** Section [KeyFrames]: the semantic selector's keys plus these. */
	struct TOptions : public TTableOptions<TOptions>
	{
		CSemanticKeyFrameSelector::TOptions semantic;
		std::string policy = "semantic";  //!< semantic | orbslam
		double forceTrackedRatio = 0.25;  //!< semantic: insert at once below this share of the reference's points
		double semanticRefRatio =
			0.9;  //!< semantic: Algorithm 1's choice is inserted only below this share (1 = always)
		/** semantic: what the motion amplitude D (eq. 12-17) is measured against: "tracker" (the
		 * keyframe sharing most points with the frame, ORB-SLAM2's reference) or "previous"
		 * (Algorithm 1's own F_ref: the keyframe its last interval chose). */
		std::string motionReference = "tracker";
		int orbMaxFrames = 30;      //!< orbslam: a keyframe at least this often (ORB-SLAM2: the frame rate)
		int orbMinFrames = 0;       //!< orbslam: no keyframe sooner than this
		double orbRefRatio = 0.75;  //!< orbslam: c2 threshold on inliers / reference points
		double closeDepth = 3.2;    //!< orbslam: "close" points (ORB-SLAM2's ThDepth, 40 baselines), m

		/** Every option once: key, member, range, help (load, dump and keys come from it). */
		COptionTable table();
	};

	/** What the map knows about the reference keyframe, for the decision. */
	struct TReference
	{
		std::size_t frameId = 0;
		std::size_t points = 0;  //!< map points it sees
	};

	/** A decision: the frame to turn into a keyframe. */
	struct TDecision
	{
		std::size_t frameId = 0;
		bool forced = false;  //!< by the safety net, not by the policy
	};

	/** Checks the options; throws InputError for an unknown policy or invalid values. */
	explicit CKeyFrameInserter(const TOptions& opts);

	/** Feeds one tracked frame; `motion` is D (eq. 16) to the reference keyframe. */
	std::optional<TDecision> addFrame(const TFrame& f, const TReference& ref, double motion);
	/** Tells the inserter that `frameId` became a keyframe (resets the orbslam counters). */
	void keyFrameInserted(std::size_t frameId) { lastKeyFrame_ = frameId; }
	const TOptions& options() const { return opts_; }

	/** How many of Algorithm 1's choices were not inserted because the map already covered them. */
	std::size_t redundantChoices() const { return redundantChoices_; }

   private:
	/** How well a tracked frame was covered by the map when it was tracked (ORB-SLAM2's c2). */
	struct TCoverage
	{
		std::size_t frameId = 0;
		bool seesNewContent = true;
	};
	/** ORB-SLAM2's "need close points": few close points tracked while many close ones are not. */
	bool needsClosePoints(const TFrame& f) const;

	TOptions opts_;
	CSemanticKeyFrameSelector selector_;
	std::optional<std::size_t> lastKeyFrame_;
	std::deque<TCoverage> coverage_;  //!< the frames of the open interval
	std::size_t redundantChoices_ = 0;
};
}  // namespace mrpt_yesslam
