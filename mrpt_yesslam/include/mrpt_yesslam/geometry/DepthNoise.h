#pragma once
// The depth sensor's noise, one model for every stage that weighs or gates a measured depth
// (issue 42): the pose solve, local and global bundle adjustment, point fusion, see-through
// culling and the loop's relative pose. Formerly three options ([Tracking] and [LocalMapping]
// depthNoise, [LoopClosing] refineDepthNoise) with four formulas for one sensor.
#include <cmath>

#include "mrpt_yesslam/util/OptionTable.h"

namespace mrpt_yesslam
{
/** Section [Camera]: structured light's depth error, sigma_z = depthNoise x z^depthNoiseExponent.
 * The random part grows with z^2 (a constant disparity noise; Khoshelham and Elberink 2012 measured
 * 0.0015-0.003 /m for the Kinect v1; the Xtion is the same design), but what a SLAM system meets
 * on a real sensor also holds the error that does not average out between frames: the disparity
 * distortion, which grows as the disparity falls (Herrera, Kannala and Heikkila 2012), and the
 * far-depth bias. So the default grows with z^2.5: the same 2.5 mm at 1 m, 1.4 cm at 2 m, 3.9 cm
 * at 3 m. ORB-SLAM2's RGB-D weighting (bf = 40 for TUM) amounts to 0.025 z^2: weaker still.
 * Measured (docs/benchmarks.md, "The depth error grows faster than z^2"): the real Bonn windows
 * and every --real-sensor sim better, the TUM fr1 frames as good. z^3 was better still on the
 * Xtion but let a walker no detector reports drag the camera (near points gained too much weight
 * over the far static scene): of 2, 2.5 and 3, 2.5 is the one that keeps that case. */
struct TDepthNoise : public TTableOptions<TDepthNoise>
{
	/** sigma_z (m) at 1 m, at a pixel known exactly; 0 = depth is not a measurement
	 * (reprojection only: the paper's eq. 7 and 24). */
	double depthNoise = 0.0025;
	/** How sigma_z grows with the depth: 2 = the random disparity noise alone; more = with the
	 * errors that grow faster with distance (see above). */
	double depthNoiseExponent = 2.5;
	/** Beyond this depth (m) a keypoint's depth is not a measurement in the pose solve, bundle
	 * adjustment and the loop's final pose solve: the keypoint counts by its pixel alone, and in BA
	 * a point no keyframe of the window measures nearer keeps its position (as one without depth).
	 * The far end of structured light is where its depth is least trusted (ORB-SLAM2 makes points
	 * only from depths within 40 baselines, [KeyFrames] closeDepth here); 0 = every depth. */
	double farDepth = 0.0;

	/** A model that uses no depth (depthNoise 0). */
	static TDepthNoise none()
	{
		TDepthNoise n;
		n.depthNoise = 0;
		return n;
	}
	/** Whether depth enters the cost at all. */
	bool used() const { return depthNoise > 0; }
	/** Whether a depth z read at a keypoint enters a cost as a measurement (a depth, used, not far). */
	bool measures(double z) const { return used() && z > 0 && (farDepth <= 0 || z <= farDepth); }
	/** The std (m) of a depth z read at a keypoint known to `pixelSigma` pixels (ORB: scaleFactor
	 * ^ octave): on a slanted surface or near an edge the depth changes within that, so a coarse
	 * keypoint's depth is as uncertain as its position (ORB-SLAM2 weighs the depth's virtual
	 * right-image coordinate by the pixel's sigma). Tracking and the gates pass 1: see CTracker. */
	double sigma(double z, double pixelSigma = 1.0) const
	{
		return depthNoise * std::pow(z, depthNoiseExponent) * pixelSigma;
	}

	/** Every option once: key, member, range, help (load, dump and keys come from it). */
	COptionTable table();
};
}  // namespace mrpt_yesslam
