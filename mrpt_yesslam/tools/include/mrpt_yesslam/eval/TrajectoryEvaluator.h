#pragma once
// ATE and RPE exactly as the TUM RGB-D benchmark tools (evaluate_ate.py, evaluate_rpe.py with
// --fixed_delta) compute them, so that our numbers compare with every paper's. See
// ../shared/docs/EVALUATION.md for the semantics reproduced here, quirks included.
#include <Eigen/Core>
#include <string>
#include <utility>
#include <vector>

#include "mrpt_yesslam/geometry/Alignment.h"
#include "mrpt_yesslam/io/Trajectory.h"

namespace mrpt_yesslam
{
/** Summary statistics of a list of errors (numpy semantics: population std, mid-mean median). */
struct TErrorStats
{
	std::size_t n = 0;
	double rmse = 0, mean = 0, median = 0, std = 0, min = 0, max = 0;
	/** Computes the statistics of `v` (all zero when empty). */
	static TErrorStats of(const std::vector<double>& v);
};

/** How to associate and compare two trajectories (the TUM tools' defaults). */
struct TEvalOptions
{
	double maxDiff = 0.02;  //!< association window, s
	double offset = 0.0;    //!< added to estimate stamps, s
	bool sim3 = false;      //!< estimate scale too (Umeyama); the TUM tool has no such mode
	/** Align the estimate to the ground truth (the TUM tools always do); false: compare as it is,
	 * for estimates already in the ground truth's frame (a run localised in a saved map). */
	bool align = true;
	double rpeDelta = 1.0;          //!< RPE pair spacing
	bool rpeDeltaInFrames = false;  //!< spacing in frames instead of seconds
};

/** Absolute trajectory error after rigid (or Sim(3)) alignment. */
struct TAteResult
{
	TErrorStats stats;  //!< of the position residual norms, metres
	TAlignment alignment;
	std::vector<double> stamps;                   //!< ground-truth stamps of the matched pairs, in time order
	std::vector<Eigen::Vector3d> gt, estAligned;  //!< matched positions
	std::vector<double> errors;                   //!< residual norm per pair
};

/** Relative pose error over fixed-delta pairs. */
struct TRpeResult
{
	std::size_t pairs = 0;
	TErrorStats trans;   //!< metres per delta
	TErrorStats rotDeg;  //!< degrees per delta
};

/** ATE: associate (greedy, one-to-one), align, residuals. Throws InputError (naming `estName`)
 * when fewer than 3 poses can be matched. */
TAteResult computeAte(const TTrajectory& gt, const TTrajectory& est, const TEvalOptions& opts,
					  const std::string& gtName = "ground truth", const std::string& estName = "estimate");

/** RPE with evaluate_rpe.py's --fixed_delta semantics; `scale` multiplies estimate translations
 * (1 for RGB-D). Throws InputError when fewer than 2 pairs can be formed. */
TRpeResult computeRpe(const TTrajectory& gt, const TTrajectory& est, const TEvalOptions& opts, double scale = 1.0,
					  const std::string& estName = "estimate");

}  // namespace mrpt_yesslam
