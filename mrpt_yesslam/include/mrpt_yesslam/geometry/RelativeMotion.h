#pragma once
// A relative motion scaled by a factor: a velocity over another time, a damped velocity, a row's
// share of a rolling shutter's readout - the one rule the tracker, the rolling-shutter correction
// and the simulator share.
#include <mrpt/math/CVectorFixed.h>
#include <mrpt/poses/CPose3D.h>

namespace mrpt_yesslam
{
/** The pose of MRPT's SE(3) tangent [t, w] (Lie::SE<3>::log's) scaled by s: rotation exp(s w) on
 * its geodesic, translation s t (MRPT's exp is this pseudo-exponential, not the screw: the two
 * differ by the second order of a frame's motion, and every caller has used this one). */
mrpt::poses::CPose3D scaledTwist(const mrpt::math::CVectorFixedDouble<6>& twist, double s);

/** A relative motion scaled by s, as scaledTwist(log(motion), s): the same as interpolatePose
 * from the identity to `motion` (io/Trajectory), for any s, also outside 0..1. */
mrpt::poses::CPose3D scaleMotion(const mrpt::poses::CPose3D& motion, double s);
}  // namespace mrpt_yesslam
