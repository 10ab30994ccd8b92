#pragma once
// The depth sensor's noise, one model for every stage that weighs or gates a measured depth
// (issue 42): the pose solve, local and global bundle adjustment, point fusion, see-through
// culling and the loop's relative pose. Formerly three options ([Tracking] and [LocalMapping]
// depthNoise, [LoopClosing] refineDepthNoise) with four formulas for one sensor.
#include "mrpt_yesslam/util/OptionTable.h"

namespace mrpt_yesslam
{
/** Section [Camera]: structured light's depth noise, sigma_z = depthNoise x z^2 (Khoshelham and
 * Elberink 2012 measured about 0.0015-0.003 /m for the Kinect v1; the Xtion is the same design). */
struct TDepthNoise : public TTableOptions<TDepthNoise>
{
	/** sigma_z = depthNoise x z^2 (m) at a pixel known exactly; 0 = depth is not a measurement
	 * (reprojection only: the paper's eq. 7 and 24). */
	double depthNoise = 0.0025;

	/** A model that uses no depth (depthNoise 0). */
	static TDepthNoise none()
	{
		TDepthNoise n;
		n.depthNoise = 0;
		return n;
	}
	/** Whether depth enters the cost at all. */
	bool used() const { return depthNoise > 0; }
	/** The std (m) of a depth z read at a keypoint known to `pixelSigma` pixels (ORB: scaleFactor
	 * ^ octave): on a slanted surface or near an edge the depth changes within that, so a coarse
	 * keypoint's depth is as uncertain as its position (ORB-SLAM2 weighs the depth's virtual
	 * right-image coordinate by the pixel's sigma). Tracking and the gates pass 1: see CTracker. */
	double sigma(double z, double pixelSigma = 1.0) const { return depthNoise * z * z * pixelSigma; }

	/** Every option once: key, member, range, help (load, dump and keys come from it). */
	COptionTable table();
};
}  // namespace mrpt_yesslam
