#include "mrpt_yesslam/tracking/COnlinePoseFilter.h"

namespace mrpt_yesslam
{
COptionTable COnlinePoseFilter::TOptions::table()
{
	COptionTable t("OnlinePose");
	t.real("positionSigma", positionSigma, 0, 1,
		   "m: noise of a tracked position along each world axis; the online pose (trajectory_online.txt, the frame "
		   "callback) is a causal constant-velocity Kalman filter of the tracked positions (0 = the tracked pose as "
		   "solved)");
	t.real("accelSigma", accelSigma, 0.001, 1000,
		   "m/s^2: how fast the camera's velocity may change (the filter's process noise; larger follows faster, "
		   "smooths less)");
	t.real("gate", gate, 1, 1000,
		   "a position whose distance from the filter's prediction, RMS over the three axes, exceeds this many "
		   "standard deviations restarts the filter at the measurement (a jerk)");
	t.real("maxGap", maxGap, 0.001, 100, "s: a longer time since the previous frame restarts the filter");
	return t;
}

void COnlinePoseFilter::start(double t, const Eigen::Vector3d& p)
{
	TState s;
	s.t = t;
	s.p = p;
	s.v.setZero();
	// The velocity is unknown at a start: a walking camera's, a metre a second at most.
	s.P << opts_.positionSigma * opts_.positionSigma, 0, 0, 1.0;
	state_ = s;
}

mrpt::poses::CPose3D COnlinePoseFilter::update(double t, const mrpt::poses::CPose3D& measured, bool tracked,
											   bool mapJumped)
{
	const Eigen::Vector3d z(measured.x(), measured.y(), measured.z());
	const double dt = state_ ? t - state_->t : 0.0;
	jumped_ = false;
	if (opts_.positionSigma <= 0 || !tracked)
	{
		state_.reset();
		return measured;
	}
	if (!state_ || mapJumped || !(dt > 0) || dt > opts_.maxGap)
	{
		start(t, z);
		return measured;
	}
	TState& s = *state_;
	// Predict: constant velocity, white acceleration (discrete, piecewise constant over dt).
	Eigen::Matrix2d F;
	F << 1, dt, 0, 1;
	const double a2 = opts_.accelSigma * opts_.accelSigma;
	Eigen::Matrix2d Q;
	Q << a2 * dt * dt * dt * dt / 4, a2 * dt * dt * dt / 2, a2 * dt * dt * dt / 2, a2 * dt * dt;
	const Eigen::Vector3d pPred = s.p + dt * s.v;
	const Eigen::Matrix2d P = F * s.P * F.transpose() + Q;
	const double R = opts_.positionSigma * opts_.positionSigma, S = P(0, 0) + R;
	const Eigen::Vector3d y = z - pPred;
	// The innovation's RMS over the three axes, in standard deviations, against the gate.
	if (y.squaredNorm() / S > 3 * opts_.gate * opts_.gate)
	{
		jumped_ = true;
		start(t, z);
		return measured;
	}
	const Eigen::Vector2d K(P(0, 0) / S, P(1, 0) / S);
	s.p = pPred + K[0] * y;
	s.v = s.v + K[1] * y;
	s.P = (Eigen::Matrix2d::Identity() - K * Eigen::RowVector2d(1, 0)) * P;
	s.t = t;
	mrpt::poses::CPose3D out = measured;
	out.x(s.p.x());
	out.y(s.p.y());
	out.z(s.p.z());
	return out;
}
}  // namespace mrpt_yesslam
