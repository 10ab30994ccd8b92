#pragma once
// One evaluation run (ATE + RPE) and its two printed forms: "key: value" lines and JSON. The app
// and yesslam-eval both print through here, so the keys never drift apart.
#include <string>

#include "mrpt_yesslam/eval/TrajectoryEvaluator.h"

namespace mrpt_yesslam
{
/** Everything one evaluation produced. */
struct TEvalReport
{
	TEvalOptions options;
	TAteResult ate;
	bool hasRpe = false;
	TRpeResult rpe;
	std::string rpeProblem;  //!< why RPE is missing, when it is
	std::size_t gtPoses = 0, estPoses = 0;
	/** Frame-to-frame steps between consecutive matched pairs (metres): the aligned estimate's
	 * and the ground truth's step lengths, and `jitter`, the length of their difference (the
	 * estimate's own per-frame error: a still camera with jitter steps while the truth does not). */
	TErrorStats stepEst, stepGt, jitter;
};

/** Runs ATE and RPE; ATE problems throw, an RPE problem is recorded in rpeProblem. */
TEvalReport evaluateTrajectories(const TTrajectory& gt, const TTrajectory& est, const TEvalOptions& opts,
								 const std::string& gtName, const std::string& estName);

/** "key: value" lines: ate_pairs, ate_rmse, ate_mean, ate_median, ate_std, ate_min, ate_max,
 * rpe_pairs, rpe_trans_rmse, rpe_trans_mean, rpe_trans_median, rpe_rot_rmse_deg, ..., step_est_median,
 * step_gt_median, jitter_median, jitter_rmse */
std::string formatEvalKeyValues(const TEvalReport& r);

/** The ATE residual of every matched pair as CSV (header "stamp,error,dx,dy,dz": ground-truth
 * stamp, residual norm and aligned estimate minus ground truth, metres, in the ground truth's
 * frame), in time order: where along a run the error is, which the summary figures do not say. */
std::string formatAteErrorsCsv(const TAteResult& ate);

/** The same keys as JSON, plus "alignment": {rotation, translation, scale, type}. */
std::string formatEvalJson(const TEvalReport& r);
}  // namespace mrpt_yesslam
