#pragma once
// A geometric check beside the semantic mask (issue 14), so that an imperfect mask cannot drag the camera. The flood
// fill leaves some of the keypoints on a person unmasked; moving coherently they can outvote a thin static background,
// and a result that hinges on the fill's tuning follows. The check does not trust the fill where it cannot be sure:
// - A keypoint inside a dynamic detection's box (grown by boxMargin) but outside its mask is
//   "uncertain": it may be background seen between the person's limbs, or the person itself.
//   Since 2026-11-29 this box part is on only for localisation in a loaded map (`boxes = auto`): while mapping on the
//   real Xtion crowd it took away the background between the people, whom the mask and the mover check below keep out;
//   a read-only map cannot cull what people left in it, and there it helps.
//   Keypoints where the mover check found a mover are uncertain for a few frames either way.
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
// - Movers no detector reports (a missed person, a pushed chair) have no box. Close to the camera
//   they also carry most of the information (depth noise grows with z^2, pixel parallax with 1/z),
//   so the solve bends to them: every match of the mover passes the chi-square test, a few static
//   ones fail, and the error adds up frame after frame (an undetected walker in front of the
//   camera: a ruined run). A single residual cannot tell, a group can: after each solve the inliers
//   are grouped into depth-coherent surfaces (image cells split at depth gaps, joined with
//   neighbours at the same depth), and each group is left out in turn (one Gauss-Newton step from
//   the estimate). A static surface still fits the pose the others give; a mover's members then
//   miss together, far beyond what independent noise allows (n |mean whitened residual|^2 over a
//   chi-square bound). The group that misses worst leaves when its mean displacement is at least
//   moverShift; else the others are tested again without it (their misfit may be its pull) and
//   the worst of them that still misses and moved that far leaves, if any. Then the pose is
//   re-estimated, up to three times, never more than half of the inliers. The step is taken on the
//   whole cost the pose solve minimises, the motion model's prior included. This is a
//   group-deletion diagnostic (Cook's distance) on StaticFusion's and Co-Fusion's idea that a
//   region's residual, not a point's, says what moves.
#include <mrpt/img/TCamera.h>
#include <mrpt/poses/CPose3D.h>

#include <opencv2/core/types.hpp>
#include <string>
#include <vector>

#include "mrpt_yesslam/feature/COrbExtractor.h"
#include "mrpt_yesslam/geometry/CPoseOptimizer.h"
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
		/** Whether keypoints inside a dynamic detection box but outside its mask are uncertain
		 * (classify): "true", "false", or "auto", which CYesSlamSystem resolves to true for
		 * localisation in a loaded map and false when mapping (a check used directly takes "auto" as
		 * false). While mapping, on the real Xtion crowd, the mask and the mover check kept people
		 * out without it and it only took the background between them away; a read-only map cannot
		 * cull what people left in it, and there it halved the error (docs/benchmarks.md, "The box
		 * part of the check"). */
		std::string boxes = "auto";
		/** Whether classify() marks keypoints in dynamic boxes (boxes resolved; "auto" = no). */
		bool boxesOn() const { return boxes == "true"; }
		double boxMargin = 0.1;  //!< a dynamic box grows by this share of its size on every side
		/** Fewer certain-static inliers than this: the check stands aside for the frame. */
		std::size_t minCertainInliers = 30;
		/** A frame with fewer certain matches than minCertainInliers but more uncertain ones (a
		 * person fills much of the view) still gets a pose when at least this many certain ones
		 * give one and, with the uncertain matches that agree with it, it has minCertainInliers
		 * inliers; otherwise it is lost (0: always lost). */
		std::size_t minBlindedCertain = 10;
		/** Box-free mover check: depth-coherent groups the others' pose cannot explain leave the solve. */
		bool movers = true;
		double moverCell = 40;     //!< image cell side of the groups, pixels
		double moverChi2 = 100;    //!< n |mean whitened residual|^2 under the others' pose above this: moving
		double moverShift = 0.01;  //!< ... and a mean displacement of at least this, metres

		/** Every option once: key, member, range, help (load, dump and keys come from it). */
		COptionTable table();
	};

	/** What the check did in one estimate. */
	struct TStats
	{
		bool applied = false;  //!< the pose came from the certain matches first
		bool blinded = false;  //!< too few certain matches and more uncertain ones: no pose
		std::size_t certain = 0, uncertain = 0, uncertainAccepted = 0;
		/** Mover check: groups and matches taken out of the solve. */
		std::size_t movingGroups = 0, movingMatches = 0;
	};

	/** Where a mover the check found is: its keypoints' box and depth range, kept for a few frames
	 * so that its next keypoints are uncertain from the start (a geometric "detection"). */
	struct TMoverRegion
	{
		cv::Rect2f box;
		float zMin = 0, zMax = 0;
		int age = 0;  //!< frames since the check last found it moving
	};

	explicit CGeometricDynamicCheck(const TOptions& opts) : opts_(opts) {}

	/** Regions of the keypoints `moving` (indices into f), split where their depths jump. */
	std::vector<TMoverRegion> moverRegions(const TFeatures& f, const std::vector<std::size_t>& moving) const;
	/** Marks uncertain the static keypoints inside a region (grown by boxMargin, depth within
	 * 0.3 m of its range): they join a pose only if they agree with it, and never become map points. */
	void markMovers(TFeatures& f, const std::vector<TMoverRegion>& regions) const;

	/** Sets `f.uncertain`: keypoints in a dynamic detection's grown box and not flagged dynamic. */
	void classify(TFeatures& f, const std::vector<TDetection>& detections, const cv::Size& image) const;
	/** Eq. 7 robust to the mask: refines `guess` from the certain observations, then adds the
	 * uncertain ones (`uncertain[i]` for obs[i]) that agree with that pose. The inlier flags of
	 * rejected uncertain observations are false. Without uncertain observations it is
	 * `optimizer.refine(obs)`; with too few certain ones, not ok when the uncertain outnumber them. */
	TPoseEstimate refine(const CPoseOptimizer& optimizer, const std::vector<TPoseObservation>& obs,
						 const std::vector<bool>& uncertain, const mrpt::img::TCamera& K,
						 const mrpt::poses::CPose3D& guess, TStats* stats = nullptr) const;
	const TOptions& options() const { return opts_; }

   private:
	/** The certain observations' pose (at least `minFirst` inliers), then the uncertain ones that
	 * agree with it; not ok when fewer than `minTotal` inliers result. */
	TPoseEstimate certainFirst(const CPoseOptimizer& optimizer, const std::vector<TPoseObservation>& obs,
							   const std::vector<std::size_t>& certainIdx, const std::vector<std::size_t>& uncertainIdx,
							   const mrpt::img::TCamera& K, const mrpt::poses::CPose3D& guess, std::size_t minFirst,
							   std::size_t minTotal, TStats& st) const;
	/** The mover check's groups: the `use`d RGB-D observations as depth-coherent image surfaces. */
	std::vector<std::vector<std::size_t>> depthCoherentGroups(const std::vector<TPoseObservation>& obs,
															  const std::vector<bool>& use,
															  const mrpt::img::TCamera& K) const;
	/** The mover check on a finished estimate `e` of `obs` (see the file comment). */
	TPoseEstimate rejectMovingClusters(const CPoseOptimizer& optimizer, const std::vector<TPoseObservation>& obs,
									   const mrpt::img::TCamera& K, TPoseEstimate e, TStats& st) const;
	TOptions opts_;
};
}  // namespace mrpt_yesslam
