#pragma once
// The closed-form alignment of two point sets (Horn / Umeyama): the TUM tools' ATE alignment and
// the keyframe selector's motion amplitude use the same one, so it lives with the geometry the SLAM
// library is built on rather than with the evaluator.
#include <Eigen/Core>

#include <vector>

namespace mrpt_yesslam
{
/** The transform that maps estimate positions onto ground truth: gt ~ scale * R * est + t. */
struct TAlignment
{
	Eigen::Matrix3d R = Eigen::Matrix3d::Identity();
	Eigen::Vector3d t = Eigen::Vector3d::Zero();
	double scale = 1.0;
	bool sim3 = false;  //!< true when the scale was estimated (monocular estimates)
};

/** The rigid (sim3=false) or similarity alignment of `model` onto `data` (Horn/Umeyama closed form
 * with the reflection fix), exactly as evaluate_ate.py's align(). Needs at least 3 points. */
TAlignment alignPositions(const std::vector<Eigen::Vector3d>& model, const std::vector<Eigen::Vector3d>& data,
						  bool sim3);
}  // namespace mrpt_yesslam
