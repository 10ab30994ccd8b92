#pragma once
// Loop candidates labelled by a ground truth (issue 64): which of the keyframe pairs that a run's
// appearance search produced (loop_candidates.csv) were true revisits, and what each stage of loop
// detection did with the true and the false ones.
#include <map>
#include <string>
#include <vector>

#include "mrpt_yesslam/io/Trajectory.h"

namespace mrpt_yesslam
{
/** When a pair counts as a true revisit. */
struct TLoopLabelOptions
{
	double maxDistance = 0.5;  //!< m between the two cameras' true positions
	double maxAngleDeg = 30;   //!< between their viewing directions (a roll about the axis keeps the view)
	/** Each camera's view centre this far ahead must lie in the other's view (the views overlap). */
	double viewDepth = 2.0;
	double halfFovXDeg = 29, halfFovYDeg = 22.5;  //!< a Kinect's or Xtion's colour camera
	double maxDiff = 0.02;                        //!< s: the largest stamp difference to a ground-truth pose
};

/** One row of loop_candidates.csv with its label. */
struct TLabelledLoopCandidate
{
	std::size_t query = 0, candidate = 0;
	double queryStamp = 0, candidateStamp = 0, bowScore = 0, loopScore = 0, minScore = 0;
	std::string stage;
	std::size_t matches = 0, inliers = 0;
	bool labelled = false;  //!< both stamps have a ground-truth pose
	bool trueRevisit = false;
	double distance = 0, angleDeg = 0;  //!< between the true poses (when labelled)
};

/** The labels and what they add up to. */
struct TLoopLabelReport
{
	std::vector<TLabelledLoopCandidate> rows;
	std::map<std::string, std::pair<std::size_t, std::size_t>> byStage;  //!< stage -> (true, false)
	std::size_t unlabelled = 0;
	/** Detection = appearance, covisibility, age, score, grouping and consistency: a candidate is
	 * detected when it reached verification. Verification accepts. Precision of each over what it
	 * passed; recall of detection over the true candidates that were not covisible or young (those
	 * the map already links, or just left: no loop to close), of verification over the true ones
	 * it tried (not `untried`: one loop per query is taken). */
	std::size_t trueCandidates = 0, trueLoopCandidates = 0, detected = 0, trueDetected = 0, trueTried = 0, accepted = 0,
				trueAccepted = 0;
};

/** Reads loop_candidates.csv (yesslam writes it); throws InputError naming the file and line. */
std::vector<TLabelledLoopCandidate> readLoopCandidatesCsv(const std::string& path);
/** Labels each row by `gt` (camera poses, T_w_c). */
TLoopLabelReport labelLoopCandidates(std::vector<TLabelledLoopCandidate> rows, const TTrajectory& gt,
									 const TLoopLabelOptions& opts = {});
/** "key: value" lines (loop_candidates, loop_true_candidates, detection_precision, ...) and a
 * table of the stages, true / false. */
std::string formatLoopLabelReport(const TLoopLabelReport& r);
/** The rows as CSV with their labels (true_revisit, distance_m, angle_deg). */
std::string formatLabelledLoopCandidatesCsv(const TLoopLabelReport& r);
}  // namespace mrpt_yesslam
