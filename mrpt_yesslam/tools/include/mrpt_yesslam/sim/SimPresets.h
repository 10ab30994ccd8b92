#pragma once
// The camera paths of yesslam-sim's presets (CSequenceSimulator), apart from the rendering.
#include <mrpt/poses/CPose3D.h>

#include <cstdint>
#include <string>

namespace mrpt_yesslam
{
/** The camera at the near end of the simulated room looking along +x, 8 degrees down (optical
 * frame: z forward, x right, y down, as TUM and MRPT's 6-DoF camera). */
mrpt::poses::CPose3D basePose();

/** The motion of the camera relative to basePose(), in the camera frame, at time t (s) of a
 * preset's `motion` (TSimPreset::motion); `seed` varies the jitter of the still camera. */
mrpt::poses::CPose3D presetMotion(const std::string& motion, double t, uint32_t seed);
}  // namespace mrpt_yesslam
