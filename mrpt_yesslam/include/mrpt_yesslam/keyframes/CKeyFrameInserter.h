#pragma once
// Decides which tracked frames become keyframes, by one of two policies ([KeyFrames] policy), so
// that both can be compared on the same run (the paper's figure 11):
// - semantic: the paper's Algorithm 1 (CSemanticKeyFrameSelector). The decision comes when an
//   interval closes and may name an earlier frame of it. Beyond the paper, a safety net that
//   ORB-SLAM2 also has (its condition c1c): when the inliers of the current frame fall below
//   `forceTrackedRatio` of the reference keyframe's points, the view is leaving the map and a
//   keyframe is inserted at once; without it a fast turn inside an interval loses tracking.
//   Such keyframes are counted separately ("forced") in stats.json.
// - orbslam: ORB-SLAM2's Tracking::NeedNewKeyFrame for RGB-D (c1a: maxFrames since the last
//   keyframe; c1b: minFrames passed; c1c: inliers < 25% of the reference's; c2: inliers < 75% of
//   the reference's or too few close points tracked, and more than 15 inliers).
#include <optional>

#include "mrpt_yesslam/data/TFrame.h"
#include "mrpt_yesslam/keyframes/CSemanticKeyFrameSelector.h"

namespace mrpt_yesslam
{
/** The keyframe decision for a stream of tracked frames. */
class CKeyFrameInserter
{
   public:
	/** Section [KeyFrames]: the semantic selector's keys plus these. */
	struct TOptions : public mrpt::config::CLoadableOptions
	{
		CSemanticKeyFrameSelector::TOptions semantic;
		std::string policy = "semantic";  //!< semantic | orbslam
		double forceTrackedRatio = 0.25;  //!< semantic: insert at once below this share of the reference's points
		int orbMaxFrames = 30;	//!< orbslam: a keyframe at least this often (ORB-SLAM2: the frame rate)
		int orbMinFrames = 0;  //!< orbslam: no keyframe sooner than this
		double orbRefRatio = 0.75;	//!< orbslam: c2 threshold on inliers / reference points
		double closeDepth = 3.2;  //!< orbslam: "close" points (ORB-SLAM2's ThDepth, 40 baselines), m

		void loadFromConfigFile(const mrpt::config::CConfigFileBase& source, const std::string& section) override;
		void dumpToTextStream(std::ostream& out) const override;
		/** The keys loadFromConfigFile reads, for validateConfigSection. */
		static std::vector<TConfigKey> configKeys();
	};

	/** What the map knows about the reference keyframe, for the decision. */
	struct TReference
	{
		std::size_t frameId = 0;
		std::size_t points = 0;	 //!< map points it sees
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

   private:
	TOptions opts_;
	CSemanticKeyFrameSelector selector_;
	std::optional<std::size_t> lastKeyFrame_;
};
}  // namespace mrpt_yesslam
