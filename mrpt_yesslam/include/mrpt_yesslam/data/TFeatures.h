#pragma once
// The features of one frame (ORB keypoints, descriptors, depth and dynamic flags): data that
// frames, keyframes and the map hold, made by feature/COrbExtractor.
#include <opencv2/core.hpp>

#include <vector>

namespace mrpt_yesslam
{
/** The features of one frame. */
struct TFeatures
{
	std::vector<cv::KeyPoint> keypoints;  //!< level-0 pixel coordinates; octave = pyramid level
	cv::Mat descriptors;                  //!< CV_8U, 32 bytes per row
	std::vector<float> depth;             //!< metres at each keypoint, 0 = no depth
	std::vector<bool> dynamic;            //!< inside the dynamic mask (eq. 3): not used for pose
	/** In a dynamic detection's box but outside its mask (CGeometricDynamicCheck): used for pose only
	 * when consistent with the rest, never a new map point. Empty = none. */
	std::vector<bool> uncertain;
	/** The pyramid levels the extractor searched ([ORB] numLevels), whether or not a keypoint came
	 * from the coarsest: how far a map point's scale can be predicted. 0 = not known (features not
	 * made by COrbExtractor): the highest keypoint level stands for it. */
	int levels = 0;
	/** Whether keypoint i is uncertain. */
	bool isUncertain(std::size_t i) const { return i < uncertain.size() && uncertain[i]; }
	/** Number of keypoints that are not dynamic (N_sp of the keyframe selection). */
	std::size_t numStatic() const;
	/** Whether keypoint i may be used for pose and map: static and with depth in (0, maxDepth]. */
	bool usable(std::size_t i, double maxDepth) const { return !dynamic[i] && depth[i] > 0 && depth[i] <= maxDepth; }
};

}  // namespace mrpt_yesslam
