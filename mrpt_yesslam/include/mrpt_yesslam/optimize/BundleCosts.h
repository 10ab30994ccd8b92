#pragma once
// Ceres cost functions of bundle adjustment (paper eq. 24 and the local BA of section 2.2), in one
// header so that tests can check their derivatives with ceres::GradientChecker.
//
// RGB-D observations constrain the measured depth besides the pixel (u, v): a third residual
// (z_predicted - z_measured) / sigma_z with sigma_z from TDepthNoise (k z^2.5 by default: the
// structured-light model of Khoshelham & Elberink 2012 and the errors that grow faster), as dense RGB-D systems
// (DVO-SLAM, ElasticFusion) weight depth. The paper's eq. 7 / 24 use the reprojection error only, and ORB-SLAM2 uses a
// virtual stereo coordinate u - bf/z with a 1-pixel sigma, which at 3 m is a depth sigma of ~0.2 m: with keyframes a
// few centimetres apart (a handheld camera) the map's scale then hangs on weak parallax, and a few outliers bend it
// (tests/mapping: two bad pixels do). The depth term removes that.
#include <ceres/rotation.h>
#include <ceres/sized_cost_function.h>

#include <Eigen/Core>
#include <algorithm>
#include <cmath>

namespace mrpt_yesslam
{
/** Residual of one RGB-D observation: parameters world-to-camera angle-axis (3), translation (3),
 * point in the world (3); residuals (u, v) whitened by 1/sigma and the depth residual by 1/sigmaZ. */
struct TRgbdReprojectionCost
{
	/** `z` <= 0 means no depth: the third residual is then always zero. */
	TRgbdReprojectionCost(double u, double v, double z, double sigma, double sigmaZ, double fx, double fy, double cx,
						  double cy)
		: u(u),
		  v(v),
		  z(z),
		  invSigma(1.0 / sigma),
		  invSigmaZ(sigmaZ > 0 ? 1.0 / sigmaZ : 0.0),
		  fx(fx),
		  fy(fy),
		  cx(cx),
		  cy(cy)
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

/** TRgbdReprojectionCost with its Jacobians written out, what bundle adjustment solves with: the
 * same residual, derived by hand (issue 41: automatic differentiation with 9-dimensional dual
 * numbers was half of every solve's time). With R = R(w) the angle-axis rotation and
 * X_c = R X + t: dX_c/dw = -R [X]x J_r(w) (J_r: SO(3)'s right Jacobian), dX_c/dt = I,
 * dX_c/dX = R; the residual's derivative by X_c is the pinhole's and 1/sigma_z along z. */
class CRgbdReprojectionCostAnalytic : public ceres::SizedCostFunction<3, 3, 3, 3>
{
   public:
	explicit CRgbdReprojectionCostAnalytic(const TRgbdReprojectionCost& c) : c_(c) {}
	/** The residual it differentiates (the outlier test after a solve evaluates it as before). */
	const TRgbdReprojectionCost& cost() const { return c_; }
	bool Evaluate(double const* const* parameters, double* residuals, double** jacobians) const override
	{
		const double* w = parameters[0];
		const double* t = parameters[1];
		const double* X = parameters[2];
		double Rm[9];
		ceres::AngleAxisToRotationMatrix(w, Rm);  // column-major
		const Eigen::Map<const Eigen::Matrix3d> R(Rm);
		const Eigen::Vector3d Xw(X[0], X[1], X[2]);
		const Eigen::Vector3d Xc = R * Xw + Eigen::Vector3d(t[0], t[1], t[2]);
		if (Xc.z() <= 1e-3)
		{
			residuals[0] = residuals[1] = residuals[2] = 1e3;  // as TRgbdReprojectionCost: constant
			for (int k = 0; k < 3; k++)
				if (jacobians && jacobians[k]) std::fill(jacobians[k], jacobians[k] + 9, 0.0);
			return true;
		}
		const double iz = 1.0 / Xc.z();
		residuals[0] = (c_.fx * Xc.x() * iz + c_.cx - c_.u) * c_.invSigma;
		residuals[1] = (c_.fy * Xc.y() * iz + c_.cy - c_.v) * c_.invSigma;
		residuals[2] = c_.z <= 0 ? 0.0 : (Xc.z() - c_.z) * c_.invSigmaZ;
		if (!jacobians) return true;
		Eigen::Matrix3d D;  // d residual / d X_c
		D << c_.fx * iz * c_.invSigma, 0, -c_.fx * Xc.x() * iz * iz * c_.invSigma, 0, c_.fy * iz * c_.invSigma,
			-c_.fy * Xc.y() * iz * iz * c_.invSigma, 0, 0, c_.z <= 0 ? 0.0 : c_.invSigmaZ;
		using J3 = Eigen::Matrix<double, 3, 3, Eigen::RowMajor>;
		if (jacobians[0])
		{
			const Eigen::Vector3d wv(w[0], w[1], w[2]);
			const double th2 = wv.squaredNorm();
			Eigen::Matrix3d W;
			W << 0, -wv.z(), wv.y(), wv.z(), 0, -wv.x(), -wv.y(), wv.x(), 0;
			// J_r = I - (1 - cos th) / th^2 [w]x + (th - sin th) / th^3 [w]x^2; Taylor series near 0.
			double a, b;
			if (th2 < 1e-8)
			{
				a = 0.5 - th2 / 24.0;
				b = 1.0 / 6.0 - th2 / 120.0;
			}
			else
			{
				const double th = std::sqrt(th2);
				a = (1.0 - std::cos(th)) / th2;
				b = (th - std::sin(th)) / (th2 * th);
			}
			const Eigen::Matrix3d Jr = Eigen::Matrix3d::Identity() - a * W + b * W * W;
			Eigen::Matrix3d Xx;
			Xx << 0, -Xw.z(), Xw.y(), Xw.z(), 0, -Xw.x(), -Xw.y(), Xw.x(), 0;
			Eigen::Map<J3> Jw(jacobians[0]);
			Jw = -D * R * Xx * Jr;
		}
		if (jacobians[1])
		{
			Eigen::Map<J3> Jt(jacobians[1]);
			Jt = D;
		}
		if (jacobians[2])
		{
			Eigen::Map<J3> JX(jacobians[2]);
			JX = D * R;
		}
		return true;
	}

   private:
	TRgbdReprojectionCost c_;
};
}  // namespace mrpt_yesslam
