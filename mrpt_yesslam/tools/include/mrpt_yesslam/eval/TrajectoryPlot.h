#pragma once
// A top-down picture of an evaluation: ground truth and aligned estimate, the estimate coloured by
// its ATE residual, with metre axes, a colour bar and a legend. Drawn with OpenCV so it works
// headless and needs no plotting library.
#include <string>

#include "mrpt_yesslam/eval/TrajectoryEvaluator.h"

namespace mrpt_yesslam
{
/** Writes the PNG atomically. `gtFull` is drawn whole; the plane shown is the one spanned by the
 * two axes along which the ground truth extends most (x-y for TUM's motion-capture frame). */
void plotAteTopDown(const TAteResult& ate, const TTrajectory& gtFull, const std::string& pngPath,
					const std::string& title, int width = 1000, int height = 800);
}  // namespace mrpt_yesslam
