#pragma once
// The frame maps, trajectories and scenes are exported in (issue 30 item 4). Inside, the SLAM map
// lives in its first keyframe's optical frame (x right, y down, z forward), which every z-up
// consumer (octovis, octomap_server, RViz, MRPT's viewers, yesslam-render's elevation) shows lying
// on its side. Exports therefore use the MRPT/ROS convention by default: x forward, y left, z up,
// levelled by the floor plane when one is seen (the floor at z = 0, the origin under the first
// camera), else by the first camera's own axes (origin at the first camera).
#include <mrpt/math/TPoint3D.h>
#include <mrpt/poses/CPose3D.h>

#include <optional>
#include <string>
#include <vector>

#include "mrpt_yesslam/io/Trajectory.h"

namespace mrpt_yesslam
{
/** Where exports put the map: the transform from the map's internal frame and how it was found. */
struct TWorldFrame
{
	/** optical: the map's own frame (the first keyframe's camera); zup: x forward, y left, z up. */
	enum class EKind
	{
		Optical,
		ZUp
	};
	EKind kind = EKind::Optical;
	mrpt::poses::CPose3D
		worldFromMap;         //!< T_world_map: a point p of the map is worldFromMap.composePoint(p) in exports
	bool floorSeen = false;   //!< zup: levelled by a floor plane (else by the first camera's axes)
	double cameraHeight = 0;  //!< floorSeen: the first camera's height above the floor, m

	/** The header lines exports carry: the convention in words and "T_world_map: tx ty tz qx qy qz qw". */
	std::string describe() const;
};

/** "optical" or "zup" ([System] worldFrame). */
const char* worldFrameName(TWorldFrame::EKind kind);

/** The z-up frame of a map from its points (map frame) and its first camera's pose T_map_cam0.
 * The floor is the lowest horizontal plane (within 45 degrees of the camera's up) that holds enough
 * points, 0.2-4 m below the camera: the horizontal plane with the most points (RANSAC; a table top
 * serves too, being parallel) gives the up direction, and along it the lowest well-filled layer is
 * the floor, its normal refined on its own points. Without one, the camera's axes level the frame. */
TWorldFrame estimateZUpWorldFrame(const std::vector<mrpt::math::TPoint3D>& points,
								  const mrpt::poses::CPose3D& firstCamera);

/** Every pose of `traj` (T_map_c) as T_world_c. */
TTrajectory toWorldFrame(const TTrajectory& traj, const mrpt::poses::CPose3D& worldFromMap);

/** The T_world_map a trajectory file written by yesslam states in its header (nullopt: none, such
 * as ground truth or files from other tools). Throws InputError naming the file when unreadable. */
std::optional<mrpt::poses::CPose3D> readWorldFromMap(const std::string& trajectoryPath);
}  // namespace mrpt_yesslam
