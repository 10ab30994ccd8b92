#pragma once
// The pose a robot gets while it moves (trajectory_online.txt, the frame callback): each tracked
// frame's position filtered causally by a constant-velocity Kalman filter (per world axis: position
// and velocity, white-acceleration process noise), so that the single-frame solve's noise is
// averaged with the frames before it and never with later ones. Orientation, tracking's own state
// and the map are untouched: the filter only shapes what is reported. It restarts at the measured
// pose where the map jumped (a loop correction, a global BA, a relocalisation), after a loss, after
// a gap in time and where a measurement lies beyond its gate (the camera jerked).
#include <mrpt/poses/CPose3D.h>

#include <Eigen/Core>
#include <optional>

#include "mrpt_yesslam/util/OptionTable.h"

namespace mrpt_yesslam
{
/** Causal filter of the online pose. */
class COnlinePoseFilter
{
   public:
	/** Section [OnlinePose]. */
	struct TOptions : public TTableOptions<TOptions>
	{
		/** m: the noise of a tracked position along each world axis (0 = no filtering). */
		double positionSigma = 0.003;
		/** m/s^2: how fast the camera's velocity may change (the process noise). */
		double accelSigma = 2.0;
		/** A measurement whose innovation, RMS over the three axes, exceeds this many standard
		 * deviations restarts the filter. */
		double gate = 5.0;
		/** s: a longer time since the previous frame restarts the filter. */
		double maxGap = 0.2;

		COptionTable table();
	};

	COnlinePoseFilter() : COnlinePoseFilter(TOptions()) {}
	explicit COnlinePoseFilter(const TOptions& opts) : opts_(opts) {}
	/** The pose to report for the frame at `t` that tracking placed at `measured`: the filtered
	 * position with the measured orientation while `tracked`; the measured pose itself (and a
	 * restart) when not tracked, when `mapJumped` or after a gap or a rejected innovation. */
	mrpt::poses::CPose3D update(double t, const mrpt::poses::CPose3D& measured, bool tracked, bool mapJumped);
	/** Whether the last update() restarted the filter at a tracked measurement beyond its gate:
	 * the camera jerked there (trajectory_smoothed.txt does not fit across such a frame). */
	bool jumped() const { return jumped_; }
	/** Forgets the state: the next tracked frame starts it again. */
	void reset() { state_.reset(); }
	const TOptions& options() const { return opts_; }

   private:
	struct TState
	{
		double t = 0;
		Eigen::Vector3d p, v;
		// Per axis the same covariance: the axes share their noise models.
		Eigen::Matrix2d P;
	};
	void start(double t, const Eigen::Vector3d& p);

	TOptions opts_;
	std::optional<TState> state_;
	bool jumped_ = false;
};
}  // namespace mrpt_yesslam
