#pragma once
// Ground-truth files whose poses are not the camera's. TUM RGB-D ships camera poses; the Bonn RGB-D
// Dynamic dataset ships the poses of the motion-capture markers in the motion-capture frame, in the
// same TUM text format. Evaluated as they are, its RPE compares marker motion with camera motion
// (about 10 deg/s of "rotation error" on a still-correct estimate), so they are brought into the
// camera frame first, with the transform the dataset publishes.
#include <string>

#include "mrpt_yesslam/io/Trajectory.h"

namespace mrpt_yesslam
{
/** What the poses of a ground-truth file are: "tum" (the camera's, used as they are), "bonn"
 * (the Bonn dataset's marker poses, converted to the camera's) or "auto" (resolveGroundTruthFormat). */
enum class EGroundTruthFormat
{
	Tum,
	Bonn,
	Auto
};

/** Parses "tum", "bonn" or "auto" (case-insensitive); throws InputError naming `option` otherwise. */
EGroundTruthFormat parseGroundTruthFormat(const std::string& name, const std::string& option = "--gt-format");

/** Bonn marker poses to camera poses: T_cam = T_ros * T_gt * T_ros * T_m (the dataset's own
 * transform; T_m's 3x3 block, not exactly a rotation as published, is replaced by its nearest
 * rotation). Stamps are kept. */
TTrajectory bonnMarkersToCamera(const TTrajectory& markers);

/** The format of ground-truth file `path`: `format` itself unless Auto; Auto is Bonn when the
 * file's folder or name says "bonn" (the dataset's folders are rgbd_bonn_<sequence>, as RTAB-Map
 * recognises them), else Tum. */
EGroundTruthFormat resolveGroundTruthFormat(const std::string& path, EGroundTruthFormat format);

/** What a resolved format means, for the line a tool prints beside the file's name. */
std::string describeGroundTruthFormat(EGroundTruthFormat format);

/** Reads a ground-truth trajectory (readTumTrajectory) and converts it to camera poses (Auto:
 * resolveGroundTruthFormat). */
TTrajectory readGroundTruth(const std::string& path, EGroundTruthFormat format);
}  // namespace mrpt_yesslam
