#pragma once
// Camera pose from static features only (paper eq. 7): PnP with RANSAC (OpenCV) to initialise or
// recover, then Levenberg-Marquardt minimising the robust (Huber) reprojection error, in rounds that re-classify
// outliers by a chi-square test as ORB-SLAM2's pose optimisation does.
#include <mrpt/config/CLoadableOptions.h>
#include <mrpt/img/TCamera.h>
#include <mrpt/poses/CPose3D.h>

#include <Eigen/Core>
#include <optional>
#include <vector>

#include "mrpt_yesslam/util/ConfigFile.h"
#include "mrpt_yesslam/util/OptionTable.h"

namespace mrpt_yesslam
{
/** A 3D map point seen at a pixel. */
struct TPoseObservation
{
	Eigen::Vector3d world;  //!< point in the world frame, metres
	Eigen::Vector2d pixel;  //!< undistorted pixel
	double sigma = 1.0;     //!< pixel noise std (ORB: scale factor ^ octave)
	double depth = 0;       //!< measured depth at the pixel, metres (0 = none: reprojection only)
	double sigmaZ = 0;      //!< depth noise std, metres (0 = depth not used)
};

/** Outcome of a pose estimate. */
struct TPoseEstimate
{
	bool ok = false;
	mrpt::poses::CPose3D cameraInWorld;  //!< T_w_c (camera pose in the world, z forward)
	std::vector<bool> inlier;            //!< per observation
	std::size_t numInliers = 0;
	double rmsPixels = 0;  //!< reprojection RMS over inliers
	/** Per observation: in a group that CGeometricDynamicCheck found moving (empty = none). */
	std::vector<bool> moving;
	/** Whether observation i was found moving. */
	bool isMoving(std::size_t i) const { return i < moving.size() && moving[i]; }
};

/** Residual of one observation for a world-to-camera pose (angle-axis, translation): pixel
 * reprojection (u, v) / sigma (eq. 7) and, for RGB-D observations, (z - depth) / sigmaZ (zero
 * without depth); exposed so that tests can check its derivatives with ceres::GradientChecker. */
struct TReprojectionResidual
{
	TReprojectionResidual(const TPoseObservation& o, double fx, double fy, double cx, double cy)
		: X(o.world),
		  uv(o.pixel),
		  invSigma(1.0 / o.sigma),
		  depth(o.sigmaZ > 0 ? o.depth : 0.0),
		  invSigmaZ(o.sigmaZ > 0 ? 1.0 / o.sigmaZ : 0.0),
		  fx(fx),
		  fy(fy),
		  cx(cx),
		  cy(cy)
	{
	}
	template <typename T>
	bool operator()(const T* const rvec, const T* const t, T* r) const;

	Eigen::Vector3d X;
	Eigen::Vector2d uv;
	double invSigma, depth, invSigmaZ, fx, fy, cx, cy;
};

/** TReprojectionResidual at world-to-camera pose `Tcw` with its Jacobian in closed form, for a
 * left perturbation of the pose (rotation first, then translation: X_c -> exp(w) X_c + v). Cheaper
 * than automatic differentiation where many residuals are linearised once (the geometric check's
 * group test); linear predictions r + J step do not depend on the choice of pose parameters. */
void reprojectionResidualJacobian(const TReprojectionResidual& f, const mrpt::poses::CPose3D& Tcw, Eigen::Vector3d& r,
								  Eigen::Matrix<double, 3, 6, Eigen::RowMajor>& J);

/** T_w_c (MRPT camera-in-world pose) -> world-to-camera angle-axis and translation, the
 * parameters our Ceres problems optimise. */
void cameraPoseToParams(const mrpt::poses::CPose3D& Twc, double rvec[3], double t[3]);
/** The inverse of cameraPoseToParams. */
mrpt::poses::CPose3D cameraPoseFromParams(const double rvec[3], const double t[3]);

/** Pose estimation from 3D-2D correspondences. */
class CPoseOptimizer
{
   public:
	/** Section [Tracking] (the pose part). */
	struct TOptions : public TTableOptions<TOptions>
	{
		double chi2Threshold = 5.991;  //!< 2-DoF chi-square at 95% (ORB-SLAM2); 7.815 (3-DoF) with depth
		int rounds = 4;                //!< optimise, re-classify, repeat
		int iterationsPerRound = 10;
		int ransacIterations = 200;
		double ransacPixels = 4.0;    //!< PnP RANSAC inlier threshold
		std::size_t minInliers = 10;  //!< fewer: the estimate is not trusted (ok = false)

		/** Every option once: key, member, range, help (load, dump and keys come from it). */
		COptionTable table();
	};

	CPoseOptimizer() : CPoseOptimizer(TOptions()) {}
	explicit CPoseOptimizer(const TOptions& opts) : opts_(opts) {}

	/** PnP + RANSAC from scratch (no prior pose), for initialisation and relocalisation. */
	TPoseEstimate solvePnPRansac(const std::vector<TPoseObservation>& obs, const mrpt::img::TCamera& K) const;
	/** Whether each observation agrees with pose `Twc`: its chi-square passes the same test that
	 * refine() uses to tell inliers from outliers. */
	std::vector<bool> consistent(const std::vector<TPoseObservation>& obs, const mrpt::img::TCamera& K,
								 const mrpt::poses::CPose3D& Twc) const;

	/** Squared whitened residual (pixel and depth) of each observation at pose `Twc`. */
	std::vector<double> chi2(const std::vector<TPoseObservation>& obs, const mrpt::img::TCamera& K,
							 const mrpt::poses::CPose3D& Twc) const;
	/** The chi-square an observation must not exceed to be an inlier. */
	double chi2Limit(const TPoseObservation& o) const;

	/** Eq. 7: refines `initial` (T_w_c) with Huber reprojection error over rounds of outlier
	 * re-classification. `start`, when given, says which observations the first round uses (the
	 * others may join from the second round on, if they agree with the pose). */
	TPoseEstimate refine(const std::vector<TPoseObservation>& obs, const mrpt::img::TCamera& K,
						 const mrpt::poses::CPose3D& initial, const std::vector<bool>* start = nullptr) const;

	const TOptions& options() const { return opts_; }

	/** A weak prior on the pose: where the camera is expected (T_w_c) and how far it may be, in
	 * metres and radians per axis of the camera frame (the motion model's prediction). */
	struct TPosePrior
	{
		mrpt::poses::CPose3D cameraInWorld;
		double sigmaT = 0, sigmaR = 0;
	};
	/** refine() adds the prior's squared whitened deviation to its cost (none: reprojection and
	 * depth alone). */
	void setPrior(std::optional<TPosePrior> p) { prior_ = std::move(p); }

	/** The prior's term at a pose (T_w_c), as refine() weighs it: the deviation (rotation, then
	 * translation, in the left perturbation's terms of world-to-camera) and its information per
	 * axis; false without a prior. What the geometric check needs to linearise the whole cost. */
	bool priorTerm(const mrpt::poses::CPose3D& cameraInWorld, Eigen::Matrix<double, 6, 1>& deviation,
				   Eigen::Matrix<double, 6, 1>& information) const;

   private:
	/** One round of refine(): Levenberg-Marquardt on world-to-camera `R`, `t` over the
	 * observations `use` marks, Huber-weighted with each one's chi-square `limit`. */
	void solveRound(const std::vector<TReprojectionResidual>& f, const std::vector<double>& limit,
					const std::vector<bool>& use, Eigen::Matrix3d& R, Eigen::Vector3d& t) const;

	TOptions opts_;
	std::optional<TPosePrior> prior_;
};
}  // namespace mrpt_yesslam
