#pragma once
// A geometric check beside the semantic mask (issue 14), so that an imperfect mask cannot drag the
// camera. The flood fill leaves 7-14 % of the keypoints on a person unmasked; moving coherently they
// can outvote a thin static background, and a result that hinges on the fill's tuning follows. The
// check does not trust the fill where it cannot be sure:
// - A keypoint inside a dynamic detection's box (grown by boxMargin) but outside its mask is
//   "uncertain": it may be background seen between the person's limbs, or the person itself.
// - The pose is first estimated from the certain-static matches alone (outside every dynamic box);
//   an uncertain match joins only if it agrees with that pose (its chi-square under it passes the
//   optimiser's own test), and the pose is refined with the certain and the agreeing ones. This is
//   DynaSLAM's "semantic prior + geometric confirmation" and DS-SLAM's idea of checking features
//   near people against the motion of the rest, done with the pose itself rather than epipolar
//   lines (RGB-D gives depth).
// - Uncertain keypoints never create map points: a person's leaked features must not become map
//   points that later drag tracking (the failure mode measured on walking_static).
// - When the certain matches are too few to carry the pose and the uncertain ones outnumber them
//   (a person fills the view), there is no pose: the frame is lost and tracking keeps its
//   prediction until the view clears (issue 14, blinded camera). With few matches of either kind
//   (a bare wall) the check stands aside and every unmasked match is used, as before.
#include <mrpt/img/TCamera.h>
#include <mrpt/poses/CPose3D.h>

#include <vector>

#include "mrpt_yesslam/feature/COrbExtractor.h"
#include "mrpt_yesslam/tracking/CPoseOptimizer.h"
#include "mrpt_yesslam/types.h"
#include "mrpt_yesslam/util/OptionTable.h"

namespace mrpt_yesslam
{
/** Marks keypoints the mask is unsure of and estimates poses that they cannot drag. */
class CGeometricDynamicCheck
{
   public:
	/** Section [GeometricCheck]. */
	struct TOptions : public TTableOptions<TOptions>
	{
		bool enabled = true;  //!< false: every unmasked keypoint is trusted (the paper)
		double boxMargin = 0.1;	 //!< a dynamic box grows by this share of its size on every side
		/** Fewer certain-static inliers than this: the check stands aside for the frame. */
		std::size_t minCertainInliers = 30;

		/** Every option once: key, member, range, help (load, dump and keys come from it). */
		COptionTable table();
	};

	/** What the check did in one estimate. */
	struct TStats
	{
		bool applied = false;  //!< the pose came from the certain matches first
		bool blinded = false;  //!< too few certain matches and more uncertain ones: no pose
		std::size_t certain = 0, uncertain = 0, uncertainAccepted = 0;
	};

	explicit CGeometricDynamicCheck(const TOptions& opts) : opts_(opts) {}

	/** Sets `f.uncertain`: keypoints in a dynamic detection's grown box and not flagged dynamic. */
	void classify(TFeatures& f, const std::vector<TDetection>& detections, const cv::Size& image) const;
	/** Eq. 7 robust to the mask: refines `guess` from the certain observations, then adds the
	 * uncertain ones (`uncertain[i]` for obs[i]) that agree with that pose. The inlier flags of
	 * rejected uncertain observations are false. Without uncertain observations it is
	 * `optimizer.refine(obs)`; with too few certain ones, not ok when the uncertain outnumber them. */
	TPoseEstimate refine(
		const CPoseOptimizer& optimizer, const std::vector<TPoseObservation>& obs, const std::vector<bool>& uncertain,
		const mrpt::img::TCamera& K, const mrpt::poses::CPose3D& guess, TStats* stats = nullptr) const;
	const TOptions& options() const { return opts_; }

   private:
	TOptions opts_;
};
}  // namespace mrpt_yesslam
