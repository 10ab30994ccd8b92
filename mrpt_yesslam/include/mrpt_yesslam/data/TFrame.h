#pragma once
// One RGB-D frame as tracking sees it: features (with depth and dynamic flags), detections, and
// the pose tracking gave it. It becomes read-only once tracking has finished with it.
#include <mrpt/img/TCamera.h>
#include <mrpt/poses/CPose3D.h>

#include <opencv2/core.hpp>
#include <memory>
#include <vector>

#include "mrpt_yesslam/data/TFeatures.h"
#include "mrpt_yesslam/types.h"

namespace mrpt_yesslam
{
/** Id of a map point; -1 = none. */
using TPointId = long;

/** The images of a frame, kept (only) when a dense map is built from its keyframes. */
struct TFrameImages
{
	cv::Mat bgr;          //!< CV_8UC3 colour, as given (distorted)
	cv::Mat depth;        //!< CV_32FC1 metres, 0 = none, registered to the colour image
	cv::Mat dynamicMask;  //!< CV_8UC1, 255 = masked as dynamic by tracking (held objects included); empty = none
};

/** A tracked frame. */
struct TFrame
{
	std::size_t id = 0;             //!< 0-based index in the input stream
	double timestamp = 0;           //!< seconds
	mrpt::img::TCamera camera;      //!< intrinsics of the colour image
	TFeatures features;             //!< keypoints are undistorted pixel coordinates
	std::vector<cv::Vec3b> colors;  //!< BGR at each keypoint (map point colours)
	std::vector<TDetection> detections;
	std::size_t numDynamicMasked = 0;  //!< dynamic pixels in the mask (for statistics)
	/** Map point matched to each keypoint by tracking (inliers only); -1 = none. */
	std::vector<TPointId> mapPoints;
	mrpt::poses::CPose3D pose;  //!< T_w_c, camera (z forward) in the world
	/** The pose reported for this frame (onlineTrajectory, TFrameReport): `pose` with its position
	 * filtered causally ([OnlinePose]); tracking itself goes on from `pose`. */
	mrpt::poses::CPose3D onlinePose;
	bool tracked = false;                        //!< false: the pose is a motion-model guess (tracking lost)
	std::size_t numInliers = 0;                  //!< static map points that supported the pose
	std::shared_ptr<const TFrameImages> images;  //!< null unless the builder keeps images (dense mapping)

	/** Number of keypoints. */
	std::size_t size() const { return features.keypoints.size(); }
	/** Whether keypoint i may be used for pose and map: static and with usable depth. */
	bool usable(std::size_t i, double maxDepth) const { return features.usable(i, maxDepth); }
	/** The 3D point of keypoint i in the camera frame (needs depth). */
	cv::Point3d backProject(std::size_t i) const;
};
}  // namespace mrpt_yesslam
