#include "mrpt_yesslam/geometry/CPoseOptimizer.h"

#include <ceres/ceres.h>
#include <ceres/rotation.h>
#include <mrpt/config/CConfigFileBase.h>
#include <mrpt/math/CMatrixFixed.h>

#include <cmath>
#include <opencv2/calib3d.hpp>

namespace mrpt_yesslam
{
COptionTable CPoseOptimizer::TOptions::table()
{
	COptionTable t("Tracking");
	t.real("chi2Threshold", chi2Threshold, 0.1, 1000, "pose from static features (eq. 7): Huber reprojection error, outliers re-classified above this chi-square");
	t.real("depthNoise", depthNoise, 0, 1, "depth residual sigma_z = depthNoise x z^2 (m); 0 = reprojection only (eq. 7)");
	t.integer("rounds", rounds, 1, 100, "optimise, re-classify outliers, repeat");
	t.integer("iterationsPerRound", iterationsPerRound, 1, 1000, "Levenberg-Marquardt iterations per round");
	t.integer("ransacIterations", ransacIterations, 1, 100000, "PnP RANSAC iterations (initialisation, relocalisation)");
	t.real("ransacPixels", ransacPixels, 0.1, 100, "PnP RANSAC inlier threshold, pixels");
	t.count("minInliers", minInliers, 3, 100000, "fewer inliers: the pose is not trusted");
	return t;
}

template <typename T>
bool TReprojectionResidual::operator()(const T* const rvec, const T* const t, T* r) const
{
	const T Xw[3] = {T(X.x()), T(X.y()), T(X.z())};
	T Xc[3];
	ceres::AngleAxisRotatePoint(rvec, Xw, Xc);
	Xc[0] += t[0];
	Xc[1] += t[1];
	Xc[2] += t[2];
	if (Xc[2] <= T(1e-6))
	{
		// Behind the camera: a large constant residual keeps the problem well defined.
		r[0] = T(1e3);
		r[1] = T(1e3);
		r[2] = T(0.0);
		return true;
	}
	r[0] = (T(fx) * Xc[0] / Xc[2] + T(cx) - T(uv.x())) * T(invSigma);
	r[1] = (T(fy) * Xc[1] / Xc[2] + T(cy) - T(uv.y())) * T(invSigma);
	// Depth breaks the ambiguity between sideways translation and rotation that reprojection alone
	// leaves with a 60-degree field of view (ORB-SLAM2's RGB-D pose optimisation constrains depth
	// too, through its virtual stereo coordinate); without it, poses from exact simulated data were
	// off by 5-8 mm.
	r[2] = depth > 0 ? (Xc[2] - T(depth)) * T(invSigmaZ) : T(0.0);
	return true;
}

template bool TReprojectionResidual::operator()<double>(const double* const, const double* const, double*) const;

void reprojectionResidualJacobian(
	const TReprojectionResidual& f, const mrpt::poses::CPose3D& Tcw, Eigen::Vector3d& r, Eigen::Matrix<double, 3, 6, Eigen::RowMajor>& J)
{
	double x, y, z;
	Tcw.composePoint(f.X.x(), f.X.y(), f.X.z(), x, y, z);
	J.setZero();
	if (z <= 1e-6)
	{
		r << 1e3, 1e3, 0.0;	 // as the residual itself: constant behind the camera
		return;
	}
	const double iz = 1.0 / z;
	r << (f.fx * x * iz + f.cx - f.uv.x()) * f.invSigma, (f.fy * y * iz + f.cy - f.uv.y()) * f.invSigma,
		f.depth > 0 ? (z - f.depth) * f.invSigmaZ : 0.0;
	// d r / d X_c
	Eigen::Matrix3d dr;
	dr << f.fx * iz * f.invSigma, 0, -f.fx * x * iz * iz * f.invSigma, 0, f.fy * iz * f.invSigma, -f.fy * y * iz * iz * f.invSigma, 0, 0,
		f.depth > 0 ? f.invSigmaZ : 0.0;
	// d X_c / d (w, v) = [ -[X_c]x  I ]
	Eigen::Matrix3d skew;
	skew << 0, -z, y, z, 0, -x, -y, x, 0;
	J.leftCols<3>() = -dr * skew;
	J.rightCols<3>() = dr;
}

void cameraPoseToParams(const mrpt::poses::CPose3D& Twc, double rvec[3], double t[3])
{
	const mrpt::poses::CPose3D Tcw = -Twc;
	const auto R = Tcw.getRotationMatrix();
	double Rm[9];
	for (int i = 0; i < 3; i++)
		for (int j = 0; j < 3; j++) Rm[j * 3 + i] = R(i, j);	// column-major for ceres
	ceres::RotationMatrixToAngleAxis(Rm, rvec);
	t[0] = Tcw.x();
	t[1] = Tcw.y();
	t[2] = Tcw.z();
}

mrpt::poses::CPose3D cameraPoseFromParams(const double rvec[3], const double t[3])
{
	double Rm[9];
	ceres::AngleAxisToRotationMatrix(rvec, Rm);
	mrpt::math::CMatrixDouble33 R;
	for (int i = 0; i < 3; i++)
		for (int j = 0; j < 3; j++) R(i, j) = Rm[j * 3 + i];
	mrpt::math::CVectorFixedDouble<3> tv;
	tv[0] = t[0];
	tv[1] = t[1];
	tv[2] = t[2];
	const mrpt::poses::CPose3D Tcw(R, tv);
	return -Tcw;
}

namespace
{
// Chi-square of each observation (squared whitened residual) at a pose.
std::vector<double> chi2All(const std::vector<TPoseObservation>& obs, const mrpt::img::TCamera& K, const double rv[3], const double t[3])
{
	std::vector<double> c(obs.size());
	for (std::size_t i = 0; i < obs.size(); i++)
	{
		TReprojectionResidual f(obs[i], K.fx(), K.fy(), K.cx(), K.cy());
		double r[3];
		f(rv, t, r);
		c[i] = r[0] * r[0] + r[1] * r[1] + r[2] * r[2];
	}
	return c;
}
}  // namespace

TPoseEstimate CPoseOptimizer::refine(
	const std::vector<TPoseObservation>& obs, const mrpt::img::TCamera& K, const mrpt::poses::CPose3D& initial,
	const std::vector<bool>* start) const
{
	TPoseEstimate out;
	if (start && start->size() == obs.size())
		out.inlier = *start;
	else
		out.inlier.assign(obs.size(), true);
	if (obs.size() < 4) return out;
	double rv[3], t[3];
	cameraPoseToParams(initial, rv, t);
	// 3 degrees of freedom with depth: the 2-DoF threshold scaled as 7.815 / 5.991.
	auto threshold = [&](const TPoseObservation& o) { return chi2Limit(o); };
	for (int round = 0; round < std::max(1, opts_.rounds); round++)
	{
		ceres::Problem problem;
		std::size_t used = 0;
		for (std::size_t i = 0; i < obs.size(); i++)
		{
			if (!out.inlier[i]) continue;
			auto* cost = new ceres::AutoDiffCostFunction<TReprojectionResidual, 3, 3, 3>(
				new TReprojectionResidual(obs[i], K.fx(), K.fy(), K.cx(), K.cy()));
			// Huber with the chi-square threshold as its corner, as ORB-SLAM2 (sqrt(5.991) pixels).
			problem.AddResidualBlock(cost, new ceres::HuberLoss(std::sqrt(threshold(obs[i]))), rv, t);
			used++;
		}
		if (used < 4) break;
		ceres::Solver::Options so;
		so.linear_solver_type = ceres::DENSE_QR;
		so.max_num_iterations = opts_.iterationsPerRound;
		so.num_threads = 1;
		so.logging_type = ceres::SILENT;
		ceres::Solver::Summary sum;
		ceres::Solve(so, &problem, &sum);
		// Re-classify every observation, so that inliers wrongly rejected early can come back.
		const auto c = chi2All(obs, K, rv, t);
		for (std::size_t i = 0; i < obs.size(); i++) out.inlier[i] = c[i] <= threshold(obs[i]);
	}
	const auto c = chi2All(obs, K, rv, t);
	double se = 0;
	for (std::size_t i = 0; i < obs.size(); i++)
		if (out.inlier[i])
		{
			out.numInliers++;
		{
			// RMS in pixels: the reprojection part only.
			TReprojectionResidual f(obs[i], K.fx(), K.fy(), K.cx(), K.cy());
			double r[3];
			f(rv, t, r);
			se += (r[0] * r[0] + r[1] * r[1]) * obs[i].sigma * obs[i].sigma;
		}
		}
	out.rmsPixels = out.numInliers ? std::sqrt(se / static_cast<double>(out.numInliers)) : 0;
	out.cameraInWorld = cameraPoseFromParams(rv, t);
	out.ok = out.numInliers >= opts_.minInliers;
	return out;
}

double CPoseOptimizer::chi2Limit(const TPoseObservation& o) const
{
	// 3 degrees of freedom with depth: the 2-DoF threshold scaled as 7.815 / 5.991.
	return o.sigmaZ > 0 && o.depth > 0 ? opts_.chi2Threshold * (7.815 / 5.991) : opts_.chi2Threshold;
}

std::vector<double> CPoseOptimizer::chi2(
	const std::vector<TPoseObservation>& obs, const mrpt::img::TCamera& K, const mrpt::poses::CPose3D& Twc) const
{
	double rv[3], t[3];
	cameraPoseToParams(Twc, rv, t);
	return chi2All(obs, K, rv, t);
}

std::vector<bool> CPoseOptimizer::consistent(
	const std::vector<TPoseObservation>& obs, const mrpt::img::TCamera& K, const mrpt::poses::CPose3D& Twc) const
{
	const auto c = chi2(obs, K, Twc);
	std::vector<bool> out(obs.size());
	for (std::size_t i = 0; i < obs.size(); i++)
		out[i] = c[i] <= chi2Limit(obs[i]);
	return out;
}

TPoseEstimate CPoseOptimizer::solvePnPRansac(const std::vector<TPoseObservation>& obs, const mrpt::img::TCamera& K) const
{
	TPoseEstimate out;
	out.inlier.assign(obs.size(), false);
	if (obs.size() < 6) return out;
	std::vector<cv::Point3d> P;
	std::vector<cv::Point2d> p;
	for (const auto& o : obs)
	{
		P.emplace_back(o.world.x(), o.world.y(), o.world.z());
		p.emplace_back(o.pixel.x(), o.pixel.y());
	}
	const cv::Matx33d Km(K.fx(), 0, K.cx(), 0, K.fy(), K.cy(), 0, 0, 1);
	cv::Mat rvec, tvec;
	std::vector<int> inl;
	bool ok = false;
	try
	{
		ok = cv::solvePnPRansac(
			P, p, Km, cv::noArray(), rvec, tvec, false, opts_.ransacIterations, static_cast<float>(opts_.ransacPixels), 0.99, inl,
			cv::SOLVEPNP_EPNP);
	}
	catch (const cv::Exception&)
	{
		ok = false;	 // degenerate configurations make OpenCV throw: no pose, not a crash
	}
	if (!ok || inl.size() < opts_.minInliers) return out;
	for (int i : inl) out.inlier[static_cast<std::size_t>(i)] = true;
	out.numInliers = inl.size();
	const double rv[3] = {rvec.at<double>(0), rvec.at<double>(1), rvec.at<double>(2)};
	const double t[3] = {tvec.at<double>(0), tvec.at<double>(1), tvec.at<double>(2)};
	out.cameraInWorld = cameraPoseFromParams(rv, t);
	out.ok = true;
	return out;
}
}  // namespace mrpt_yesslam
