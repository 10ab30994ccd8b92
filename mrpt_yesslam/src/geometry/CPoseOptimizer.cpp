#include "mrpt_yesslam/geometry/CPoseOptimizer.h"

#include <ceres/jet.h>
#include <ceres/rotation.h>
#include <mrpt/config/CConfigFileBase.h>
#include <mrpt/math/CMatrixFixed.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <opencv2/calib3d.hpp>

namespace mrpt_yesslam
{
COptionTable CPoseOptimizer::TOptions::table()
{
	COptionTable t("Tracking");
	t.real("chi2Threshold", chi2Threshold, 0.1, 1000,
		   "pose from static features (eq. 7): Huber reprojection error, outliers re-classified above this chi-square");
	t.integer("rounds", rounds, 1, 100, "optimise, re-classify outliers, repeat");
	t.integer("iterationsPerRound", iterationsPerRound, 1, 1000, "Levenberg-Marquardt iterations per round");
	t.integer("ransacIterations", ransacIterations, 1, 100000,
			  "PnP RANSAC iterations (initialisation, relocalisation)");
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
	// Depth breaks the ambiguity between sideways translation and rotation that reprojection alone leaves with a
	// 60-degree field of view (ORB-SLAM2's RGB-D pose optimisation constrains depth too, through its virtual stereo
	// coordinate); without it, even poses from exact simulated data came out off.
	r[2] = depth > 0 ? (Xc[2] - T(depth)) * T(invSigmaZ) : T(0.0);
	return true;
}

template bool TReprojectionResidual::operator()<double>(const double* const, const double* const, double*) const;
// Automatic differentiation of the residual checks the analytic Jacobian the solve uses (tests).
template bool TReprojectionResidual::operator()<ceres::Jet<double, 6>>(const ceres::Jet<double, 6>* const,
																	   const ceres::Jet<double, 6>* const,
																	   ceres::Jet<double, 6>*) const;

namespace
{
// Residual and (optionally) its Jacobian with respect to a left perturbation of the pose, at the
// point already in the camera frame: shared by the geometric check's linearisation and the
// pose solve below, so both see one model.
void residualAt(const TReprojectionResidual& f, double x, double y, double z, Eigen::Vector3d& r,
				Eigen::Matrix<double, 3, 6, Eigen::RowMajor>* J)
{
	if (z <= 1e-6)
	{
		r << 1e3, 1e3, 0.0;  // as the residual itself: constant behind the camera
		if (J) J->setZero();
		return;
	}
	const double iz = 1.0 / z;
	r << (f.fx * x * iz + f.cx - f.uv.x()) * f.invSigma, (f.fy * y * iz + f.cy - f.uv.y()) * f.invSigma,
		f.depth > 0 ? (z - f.depth) * f.invSigmaZ : 0.0;
	if (!J) return;
	// d r / d X_c
	Eigen::Matrix3d dr;
	dr << f.fx * iz * f.invSigma, 0, -f.fx * x * iz * iz * f.invSigma, 0, f.fy * iz * f.invSigma,
		-f.fy * y * iz * iz * f.invSigma, 0, 0, f.depth > 0 ? f.invSigmaZ : 0.0;
	// d X_c / d (w, v) = [ -[X_c]x  I ]
	Eigen::Matrix3d skew;
	skew << 0, -z, y, z, 0, -x, -y, x, 0;
	J->leftCols<3>() = -dr * skew;
	J->rightCols<3>() = dr;
}
}  // namespace

void reprojectionResidualJacobian(const TReprojectionResidual& f, const mrpt::poses::CPose3D& Tcw, Eigen::Vector3d& r,
								  Eigen::Matrix<double, 3, 6, Eigen::RowMajor>& J)
{
	double x, y, z;
	Tcw.composePoint(f.X.x(), f.X.y(), f.X.z(), x, y, z);
	residualAt(f, x, y, z, r, &J);
}

void cameraPoseToParams(const mrpt::poses::CPose3D& Twc, double rvec[3], double t[3])
{
	const mrpt::poses::CPose3D Tcw = -Twc;
	const auto R = Tcw.getRotationMatrix();
	double Rm[9];
	for (int i = 0; i < 3; i++)
		for (int j = 0; j < 3; j++) Rm[j * 3 + i] = R(i, j);  // column-major for ceres
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
std::vector<double> chi2All(const std::vector<TPoseObservation>& obs, const mrpt::img::TCamera& K, const double rv[3],
							const double t[3])
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

// A prior that weighs anything (both sigmas positive), or none.
const CPoseOptimizer::TPosePrior* usablePrior(const std::optional<CPoseOptimizer::TPosePrior>& p)
{
	return p && p->sigmaT > 0 && p->sigmaR > 0 ? &*p : nullptr;
}

// The prior as world-to-camera (rotation Rp, translation tp) and its information per axis.
void priorFrame(const CPoseOptimizer::TPosePrior& p, Eigen::Matrix3d& Rp, Eigen::Vector3d& tp,
				Eigen::Matrix<double, 6, 1>& info)
{
	const mrpt::poses::CPose3D Tcw = -p.cameraInWorld;
	Rp = Tcw.getRotationMatrix().asEigen();
	tp = Eigen::Vector3d(Tcw.x(), Tcw.y(), Tcw.z());
	info << Eigen::Vector3d::Constant(1.0 / (p.sigmaR * p.sigmaR)),
		Eigen::Vector3d::Constant(1.0 / (p.sigmaT * p.sigmaT));
}

// The deviation of world-to-camera (Rc, tc) from the prior's, in the left perturbation's terms:
// rotation log(Rc Rp^T), translation tc - Rc Rp^T tp.
Eigen::Matrix<double, 6, 1> priorDeviationAt(const Eigen::Matrix3d& Rp, const Eigen::Vector3d& tp,
											 const Eigen::Matrix3d& Rc, const Eigen::Vector3d& tc)
{
	const Eigen::Matrix3d D = Rc * Rp.transpose();
	const Eigen::AngleAxisd aa(D);
	Eigen::Matrix<double, 6, 1> d;
	d << aa.angle() * aa.axis(), tc - D * tp;
	return d;
}
}  // namespace

bool CPoseOptimizer::priorTerm(const mrpt::poses::CPose3D& cameraInWorld, Eigen::Matrix<double, 6, 1>& deviation,
							   Eigen::Matrix<double, 6, 1>& information) const
{
	const TPosePrior* p = usablePrior(prior_);
	if (!p) return false;
	Eigen::Matrix3d Rp;
	Eigen::Vector3d tp;
	priorFrame(*p, Rp, tp, information);
	const mrpt::poses::CPose3D Tcw = -cameraInWorld;
	deviation = priorDeviationAt(Rp, tp, Tcw.getRotationMatrix().asEigen(), Eigen::Vector3d(Tcw.x(), Tcw.y(), Tcw.z()));
	return true;
}

void CPoseOptimizer::solveRound(const std::vector<TReprojectionResidual>& f, const std::vector<double>& limit,
								const std::vector<bool>& use, Eigen::Matrix3d& R, Eigen::Vector3d& t) const
{
	// Levenberg-Marquardt on the six pose parameters with the analytic Jacobian (left
	// perturbation), Huber-weighted with the chi-square limit as its corner, as ORB-SLAM2's g2o pose
	// optimisation. Formerly a Ceres problem with automatic differentiation built every round: the
	// same cost and minimum, but problem construction and dual numbers for a 6-parameter problem
	// cost more than the solve (issue 41: tracking's largest own share). The normal equations are
	// 6x6, so one LDLT per step.
	using Mat6 = Eigen::Matrix<double, 6, 6>;
	using Vec6 = Eigen::Matrix<double, 6, 1>;
	// Huber's rho on a squared residual s with corner b (Ceres' HuberLoss(sqrt(b))): s inside,
	// 2 sqrt(b s) - b outside; its derivative is the weight of the normal equations.
	const auto rho = [](double s, double b) { return s <= b ? s : 2.0 * std::sqrt(b * s) - b; };
	// The prior (setPrior) as world-to-camera, its deviation in the left perturbation's terms:
	// rotation log(R Rp^T), translation t - R Rp^T tp; its Jacobian is the identity up to terms in
	// the deviation itself (small by construction), which Gauss-Newton may drop.
	Eigen::Matrix3d Rp = Eigen::Matrix3d::Identity();
	Eigen::Vector3d tp = Eigen::Vector3d::Zero();
	Vec6 priorInfo = Vec6::Zero();
	if (const TPosePrior* p = usablePrior(prior_)) priorFrame(*p, Rp, tp, priorInfo);
	const bool hasPrior = priorInfo.squaredNorm() > 0;
	const auto priorDeviation = [&](const Eigen::Matrix3d& Rc, const Eigen::Vector3d& tc)
	{ return priorDeviationAt(Rp, tp, Rc, tc); };
	const auto cost = [&](const Eigen::Matrix3d& Rc, const Eigen::Vector3d& tc)
	{
		double c = 0;
		if (hasPrior)
		{
			const Vec6 d = priorDeviation(Rc, tc);
			c += d.dot(priorInfo.cwiseProduct(d));
		}
		for (std::size_t i = 0; i < f.size(); i++)
		{
			if (!use[i]) continue;
			const Eigen::Vector3d Xc = Rc * f[i].X + tc;
			Eigen::Vector3d r;
			residualAt(f[i], Xc.x(), Xc.y(), Xc.z(), r, nullptr);
			c += rho(r.squaredNorm(), limit[i]);
		}
		return c;
	};
	double lambda = 1e-4;  // Ceres' initial trust region of 1e4, as the solve this replaces
	int iterations = 0;
	while (iterations < opts_.iterationsPerRound)
	{
		Mat6 H = Mat6::Zero();
		Vec6 g = Vec6::Zero();
		double c0 = 0;
		for (std::size_t i = 0; i < f.size(); i++)
		{
			if (!use[i]) continue;
			const Eigen::Vector3d Xc = R * f[i].X + t;
			Eigen::Vector3d r;
			Eigen::Matrix<double, 3, 6, Eigen::RowMajor> J;
			residualAt(f[i], Xc.x(), Xc.y(), Xc.z(), r, &J);
			const double s = r.squaredNorm();
			c0 += rho(s, limit[i]);
			const double w = s <= limit[i] ? 1.0 : std::sqrt(limit[i] / s);
			H.noalias() += w * J.transpose() * J;
			g.noalias() += w * J.transpose() * r;
		}
		if (hasPrior)
		{
			const Vec6 d = priorDeviation(R, t);
			c0 += d.dot(priorInfo.cwiseProduct(d));
			H.diagonal() += priorInfo;
			g += priorInfo.cwiseProduct(d);
		}
		if (g.lpNorm<Eigen::Infinity>() < 1e-10) return;  // at the minimum
		bool stepped = false;
		while (!stepped && iterations < opts_.iterationsPerRound)
		{
			iterations++;
			Mat6 A = H;
			for (int k = 0; k < 6; k++) A(k, k) += lambda * std::max(H(k, k), 1e-6);
			const Vec6 dx = A.ldlt().solve(-g);
			if (!dx.allFinite()) return;
			const Eigen::Vector3d w = dx.head<3>();
			const double angle = w.norm();
			const Eigen::Matrix3d dR =
				angle > 0 ? Eigen::AngleAxisd(angle, w / angle).toRotationMatrix() : Eigen::Matrix3d::Identity();
			const Eigen::Matrix3d R1 = dR * R;
			const Eigen::Vector3d t1 = dR * t + dx.tail<3>();
			const double c1 = cost(R1, t1);
			if (c1 < c0)
			{
				R = R1;
				t = t1;
				lambda = std::max(lambda / 10.0, 1e-12);
				stepped = true;
				// Ceres' function tolerance: a relative decrease this small is convergence.
				if (c0 - c1 <= 1e-6 * c0 || dx.norm() <= 1e-8 * (1.0 + t.norm())) return;
			}
			else
				lambda *= 10.0;
		}
	}
}

TPoseEstimate CPoseOptimizer::refine(const std::vector<TPoseObservation>& obs, const mrpt::img::TCamera& K,
									 const mrpt::poses::CPose3D& initial, const std::vector<bool>* start) const
{
	TPoseEstimate out;
	if (start && start->size() == obs.size())
		out.inlier = *start;
	else
		out.inlier.assign(obs.size(), true);
	if (obs.size() < 4) return out;
	double rv[3], t[3];
	cameraPoseToParams(initial, rv, t);
	std::vector<TReprojectionResidual> f;
	f.reserve(obs.size());
	for (const auto& o : obs) f.emplace_back(o, K.fx(), K.fy(), K.cx(), K.cy());
	std::vector<double> limit(obs.size());
	for (std::size_t i = 0; i < obs.size(); i++) limit[i] = chi2Limit(obs[i]);  // 3 DoF with depth
	Eigen::Matrix3d R;
	{
		double Rm[9];
		ceres::AngleAxisToRotationMatrix(rv, Rm);
		R = Eigen::Map<const Eigen::Matrix3d>(Rm);  // column-major, as ceres writes it
	}
	Eigen::Vector3d tv(t[0], t[1], t[2]);
	for (int round = 0; round < std::max(1, opts_.rounds); round++)
	{
		if (std::count(out.inlier.begin(), out.inlier.end(), true) < 4) break;
		solveRound(f, limit, out.inlier, R, tv);
		// Re-classify every observation, so that inliers wrongly rejected early can come back.
		for (std::size_t i = 0; i < obs.size(); i++)
		{
			const Eigen::Vector3d Xc = R * f[i].X + tv;
			Eigen::Vector3d r;
			residualAt(f[i], Xc.x(), Xc.y(), Xc.z(), r, nullptr);
			out.inlier[i] = r.squaredNorm() <= limit[i];
		}
	}
	// RMS in pixels over the inliers: the reprojection part only (whitened by 1/sigma, so scaled back).
	double se = 0;
	for (std::size_t i = 0; i < obs.size(); i++)
		if (out.inlier[i])
		{
			out.numInliers++;
			const Eigen::Vector3d Xc = R * f[i].X + tv;
			Eigen::Vector3d r;
			residualAt(f[i], Xc.x(), Xc.y(), Xc.z(), r, nullptr);
			se += (r[0] * r[0] + r[1] * r[1]) * obs[i].sigma * obs[i].sigma;
		}
	{
		double Rm[9];
		Eigen::Map<Eigen::Matrix3d> Rmap(Rm);
		Rmap = R;
		ceres::RotationMatrixToAngleAxis(Rm, rv);
		t[0] = tv.x();
		t[1] = tv.y();
		t[2] = tv.z();
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

std::vector<double> CPoseOptimizer::chi2(const std::vector<TPoseObservation>& obs, const mrpt::img::TCamera& K,
										 const mrpt::poses::CPose3D& Twc) const
{
	double rv[3], t[3];
	cameraPoseToParams(Twc, rv, t);
	return chi2All(obs, K, rv, t);
}

std::vector<bool> CPoseOptimizer::consistent(const std::vector<TPoseObservation>& obs, const mrpt::img::TCamera& K,
											 const mrpt::poses::CPose3D& Twc) const
{
	const auto c = chi2(obs, K, Twc);
	std::vector<bool> out(obs.size());
	for (std::size_t i = 0; i < obs.size(); i++) out[i] = c[i] <= chi2Limit(obs[i]);
	return out;
}

TPoseEstimate CPoseOptimizer::solvePnPRansac(const std::vector<TPoseObservation>& obs,
											 const mrpt::img::TCamera& K) const
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
		ok = cv::solvePnPRansac(P, p, Km, cv::noArray(), rvec, tvec, false, opts_.ransacIterations,
								static_cast<float>(opts_.ransacPixels), 0.99, inl, cv::SOLVEPNP_EPNP);
	}
	catch (const cv::Exception&)
	{
		ok = false;  // degenerate configurations make OpenCV throw: no pose, not a crash
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
