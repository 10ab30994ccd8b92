#pragma once
// Ceres cost functions of bundle adjustment (paper eq. 24 and the local BA of section 2.2), in one
// header so that tests can check their derivatives with ceres::GradientChecker.
//
// RGB-D observations use ORB-SLAM2's "stereo" residual: besides the pixel (u, v) it constrains the
// virtual right-image coordinate u_r = u - bf / z, which ties each point to its measured depth with
// an error that grows with depth like a real stereo/structured-light error (bf = fx x baseline).
// The paper's eq. 7 / 24 use the reprojection error only; keeping depth makes the problem better
// conditioned when keyframes are close together, as they are for a handheld RGB-D camera.
#include <ceres/rotation.h>

namespace mrpt_yesslam
{
/** Residual of one RGB-D observation: parameters world-to-camera angle-axis (3), translation (3),
 * point in the world (3); residuals (u, v, u_r) whitened by 1/sigma. */
struct TStereoReprojectionCost
{
	/** `ur` < 0 means no depth: the third residual is then always zero. */
	TStereoReprojectionCost(double u, double v, double ur, double sigma, double fx, double fy, double cx, double cy, double bf)
		: u(u), v(v), ur(ur), invSigma(1.0 / sigma), fx(fx), fy(fy), cx(cx), cy(cy), bf(bf)
	{
	}

	template <typename T>
	bool operator()(const T* const rvec, const T* const t, const T* const X, T* r) const
	{
		T Xc[3];
		ceres::AngleAxisRotatePoint(rvec, X, Xc);
		Xc[0] += t[0];
		Xc[1] += t[1];
		Xc[2] += t[2];
		if (Xc[2] <= T(1e-3))
		{
			// Behind the camera: a constant residual (no gradient) keeps the problem defined;
			// the outlier test after the solve removes the observation.
			r[0] = r[1] = r[2] = T(1e3);
			return true;
		}
		const T iz = T(1.0) / Xc[2];
		const T pu = T(fx) * Xc[0] * iz + T(cx);
		r[0] = (pu - T(u)) * T(invSigma);
		r[1] = (T(fy) * Xc[1] * iz + T(cy) - T(v)) * T(invSigma);
		r[2] = ur < 0 ? T(0.0) : (pu - T(bf) * iz - T(ur)) * T(invSigma);
		return true;
	}

	double u, v, ur, invSigma, fx, fy, cx, cy, bf;
};
}  // namespace mrpt_yesslam
