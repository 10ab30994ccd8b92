#pragma once
// Per-pixel object labels from detection boxes, for the dense semantic map: which pixels of a
// static object's box (desk, chair, monitor, plant) belong to the object.
//
// The masker's flood fill (paper eq. 2-5) is made for people: one seed near the box centre, a fill
// that stops at depth edges. On furniture it fails where the map needs it most: the seed of a desk's
// box lands on the monitor standing on it, and a table top or chair seat seen at a slant runs
// continuously into the floor. So the dense map labels static objects differently (beyond the
// paper), as organised-point-cloud segmentation does (PCL's OrganizedConnectedComponentSegmentation
// and normal-based RegionGrowing), plus what a box tells:
// 1. Smooth-surface segments: the depth is smoothed within surfaces (structured-light depth is
//    quantised), then inside the box grown by a margin neighbouring pixels join when their normals
//    agree with each other and with the segment's mean and each lies on the other's tangent plane,
//    so a table top, its legs, the floor and the wall behind become separate segments even where
//    they touch (a concave corner has continuous depth but a normal jump).
// 2. A detection box is tight around its object: a segment that lies inside the box belongs to the
//    object; one that goes on into the margin around the box is background that the box happens to
//    cover (floor, wall). Segments seen only through gaps of the object (the wall between a desk's
//    legs) are enclosed too, but they are behind everything around them: a segment mostly occluded
//    along its outline and occluding almost nothing is left out.
// A box where no segment qualifies labels nothing, and says so (`unknown`): the map then takes no
// label evidence from its pixels rather than calling the object background.
#include <mrpt/img/TCamera.h>

#include <opencv2/core.hpp>
#include <vector>

#include "mrpt_yesslam/types.h"

namespace mrpt_yesslam
{
/** The labels of one frame. */
struct TObjectLabels
{
	cv::Mat instance;  //!< CV_16UC1, full resolution: detection index + 1 of the object at each pixel, 0 = none
	cv::Mat unknown;   //!< CV_8UC1, 255 inside a box that found no object (and no other object's pixel)
};

/** The segmenter (const, no state: safe on any thread). */
class CObjectSegmenter
{
   public:
	/** Parameters (set from [DenseMapping]). */
	struct TParams
	{
		int downsample = 2;             //!< work at 1/downsample of the image side
		double margin = 0.15;           //!< share of the box size looked at around it
		double maxNormalAngleDeg = 30;  //!< neighbours whose normals differ more are not one surface
		double planeDistance = 0.01;    //!< m at 1 m depth (grows with depth): off-tangent-plane tolerance
		double maxMarginShare = 0.25;   //!< a segment with more of its pixels in the margin is background
		double minBoxShare = 0.01;      //!< segments smaller than this share of the box are ignored
	};

	explicit CObjectSegmenter(const TParams& p) : p_(p) {}

	/** Labels the pixels of `dets` (drawn in order: later boxes over earlier ones) on `depth`
	 * (CV_32FC1 metres, 0 = none) seen by `camera` (pinhole; distortion ignored at this scale). */
	TObjectLabels segment(const cv::Mat& depth, const mrpt::img::TCamera& camera,
						  const std::vector<TDetection>& dets) const;

	const TParams& params() const { return p_; }

   private:
	TParams p_;
};
}  // namespace mrpt_yesslam
