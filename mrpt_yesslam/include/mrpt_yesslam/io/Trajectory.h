#pragma once
// Trajectories in the TUM RGB-D format: "timestamp tx ty tz qx qy qz qw" per line, camera pose in
// the world frame, '#' comment lines, fields separated by spaces, commas or tabs.
#include <mrpt/poses/CPose3D.h>

#include <string>
#include <vector>

namespace mrpt_yesslam
{
/** One timestamped pose as stored in a TUM trajectory file (quaternion as written, not normalised). */
struct TStampedPose
{
	double t = 0;                           //!< seconds
	double tx = 0, ty = 0, tz = 0;          //!< position of the camera in the world, metres
	double qx = 0, qy = 0, qz = 0, qw = 1;  //!< orientation (Hamilton, x y z w as in the file)

	/** The pose as an MRPT CPose3D (quaternion normalised). */
	mrpt::poses::CPose3D asPose() const;
	/** Builds from an MRPT pose. */
	static TStampedPose fromPose(double t, const mrpt::poses::CPose3D& p);
};

/** A trajectory: poses in file order. */
using TTrajectory = std::vector<TStampedPose>;

/** The pose a fraction `s` (0..1) of the way from `a` to `b`: position linear, orientation on the
 * rotation geodesic (what a camera moving steadily between two poses passes through). */
mrpt::poses::CPose3D interpolatePose(const mrpt::poses::CPose3D& a, const mrpt::poses::CPose3D& b, double s);

/** Places the poses of every run of untracked frames (`tracked[i]` false) that lies between two
 * tracked ones on the path between those two, by time: position linear, orientation on the
 * rotation geodesic. Runs before the first or after the last tracked pose are left as they are. */
void interpolateUntracked(TTrajectory& traj, const std::vector<bool>& tracked);

/** The TUM tools read trajectories into a dict: duplicate stamps keep the last pose. Returns the
 * poses sorted by stamp with that rule applied. */
TTrajectory uniqueSortedByTime(const TTrajectory& traj);

/** Reads a TUM trajectory; throws InputError naming the file and line for anything malformed
 * (wrong field count, non-numbers, NaN/Inf, zero-norm quaternion). An empty file gives an empty list. */
TTrajectory readTumTrajectory(const std::string& path);

/** Parses TUM trajectory text; `nameForErrors` is used in messages. */
TTrajectory parseTumTrajectory(const std::string& text, const std::string& nameForErrors);

/** Writes a TUM trajectory atomically (temp file + rename); `header` lines get a "# " prefix. */
void writeTumTrajectory(const std::string& path, const TTrajectory& traj, const std::string& header = {});

/** Formats a trajectory as TUM text (stamps with 6 decimals, the rest with 9). */
std::string formatTumTrajectory(const TTrajectory& traj, const std::string& header = {});
}  // namespace mrpt_yesslam
