#pragma once
// Ceres cost functions of bundle adjustment (paper eq. 24 and the local BA of section 2.2), in one
// header so that tests can check their derivatives with ceres::GradientChecker.
//
// RGB-D observations constrain the measured depth besides the pixel (u, v): a third residual
// (z_predicted - z_measured) / sigma_z with sigma_z = k z^2, the Kinect/structured-light noise model
// (Khoshelham & Elberink 2012), as dense RGB-D systems (DVO-SLAM, ElasticFusion) weight depth.
// The paper's eq. 7 / 24 use the reprojection error only, and ORB-SLAM2 uses a virtual stereo
// coordinate u - bf/z with a 1-pixel sigma, which at 3 m is a depth sigma of ~0.2 m: with keyframes
// a few centimetres apart (a handheld camera) the map's scale then hangs on weak parallax, and a
// few outliers bend it (tests/mapping shows 13 mm for two bad pixels). The depth term removes that.
#include <ceres/rotation.h>

namespace mrpt_yesslam
{
/** Residual of one RGB-D observation: parameters world-to-camera angle-axis (3), translation (3),
 * point in the world (3); residuals (u, v) whitened by 1/sigma and the depth residual by 1/sigmaZ. */
struct TRgbdReprojectionCost
{
	/** `z` <= 0 means no depth: the third residual is then always zero. */
	TRgbdReprojectionCost(double u, double v, double z, double sigma, double sigmaZ, double fx, double fy, double cx, double cy)
		: u(u), v(v), z(z), invSigma(1.0 / sigma), invSigmaZ(sigmaZ > 0 ? 1.0 / sigmaZ : 0.0), fx(fx), fy(fy), cx(cx), cy(cy)
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
		r[0] = (T(fx) * Xc[0] * iz + T(cx) - T(u)) * T(invSigma);
		r[1] = (T(fy) * Xc[1] * iz + T(cy) - T(v)) * T(invSigma);
		r[2] = z <= 0 ? T(0.0) : (Xc[2] - T(z)) * T(invSigmaZ);
		return true;
	}

	double u, v, z, invSigma, invSigmaZ, fx, fy, cx, cy;
};
}  // namespace mrpt_yesslam
