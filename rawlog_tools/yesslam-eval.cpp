// yesslam-eval: ATE and RPE of an estimated trajectory against ground truth, with the numbers the
// TUM RGB-D benchmark tools print.
#include <cmath>
#include <cstdio>
#include <filesystem>

#include "mrpt_yesslam/eval/EvalReport.h"
#include "mrpt_yesslam/eval/GroundTruthFormat.h"
#include "mrpt_yesslam/eval/LoopLabels.h"
#include "mrpt_yesslam/eval/TrajectoryPlot.h"
#include "mrpt_yesslam/io/Trajectory.h"
#include "mrpt_yesslam/util/AtomicFile.h"
#include "mrpt_yesslam/util/CommandLine.h"
#include "mrpt_yesslam/util/Error.h"

using namespace mrpt_yesslam;

int main(int argc, char** argv)
{
	return runTool(
		"yesslam-eval",
		[&]() -> int
		{
			std::string gtPath, estPath, jsonPath, plotPath, errorsPath, loopsPath, labelsPath, unit = "s",
																								gtFormat = "auto";
			bool noAlign = false;
			TEvalOptions o;
			CommandLine cl(
				"yesslam-eval",
				"yesslam-eval --gt GT.txt [--gt-format auto|tum|bonn] --est EST.txt [--max-diff 0.02] [--offset 0] "
				"[--sim3 | --no-align] [--rpe-delta 1] "
				"[--rpe-unit s|f] [--json OUT.json] [--errors OUT.csv] [--plot OUT.png]\n"
				"       yesslam-eval --gt GT.txt [--gt-format auto|tum|bonn] --loops RUN/loop_candidates.csv [--labels "
				"OUT.csv]",
				"Absolute trajectory error (ATE) and relative pose error (RPE) of a TUM-format trajectory, computed\n"
				"as the TUM RGB-D benchmark's evaluate_ate.py and evaluate_rpe.py --fixed_delta compute them:\n"
				"greedy one-to-one association within --max-diff, Horn/Umeyama rigid alignment, every RPE pair\n"
				"used (no random sampling). Prints one 'key: value' line per figure (metres, degrees).\n"
				"With --loops, labels every loop candidate of a yesslam run by the ground truth instead: a true\n"
				"revisit has the two keyframes' true positions within 0.5 m, their viewing directions within 30\n"
				"degrees, and the point 2 m ahead of each camera in the other's view (a Kinect's field of view).",
				{"yesslam-eval --gt groundtruth.txt --est trajectory.txt",
				 "yesslam-eval --gt gt.txt --est kf_mono.txt --sim3 --json ate.json --plot ate.png",
				 "yesslam-eval --gt rgbd_bonn_crowd/groundtruth.txt --gt-format bonn --est trajectory.txt",
				 "yesslam-eval --gt groundtruth.txt --loops run/loop_candidates.csv --labels labelled.csv"});
			cl.text("gt", "FILE", "ground-truth trajectory (TUM format)", &gtPath, true);
			cl.text("gt-format", "auto|tum|bonn",
					"what the ground truth's poses are: tum = the camera's; bonn = the Bonn RGB-D Dynamic dataset's "
					"motion-capture markers, converted to the camera with the dataset's transform; auto (default) = "
					"bonn when the file's folder or name says bonn (the dataset's rgbd_bonn_* folders), else tum "
					"(without it RPE compares marker and camera motion)",
					&gtFormat);
			cl.text("est", "FILE", "estimated trajectory (TUM format) (required unless --loops)", &estPath);
			cl.number("max-diff", "SECONDS", "largest stamp difference for an associated pair", &o.maxDiff);
			cl.number("offset", "SECONDS", "time offset added to the estimate's stamps", &o.offset);
			cl.flag("sim3",
					"align with scale too (Umeyama Sim(3), for monocular estimates); output says 'alignment: sim3'",
					&o.sim3);
			cl.flag("no-align",
					"compare the estimate as it is, without aligning it (an estimate already in the ground truth's "
					"frame, e.g. localised in a saved map); output says 'alignment: none'",
					&noAlign);
			cl.number("rpe-delta", "D", "spacing of RPE pairs, in --rpe-unit", &o.rpeDelta);
			cl.text("rpe-unit", "s|f", "RPE spacing unit: s = seconds, f = frames", &unit);
			cl.text("json", "FILE", "also write all figures and the alignment as JSON", &jsonPath);
			cl.text("errors", "FILE",
					"also write the ATE residual of every matched pair as CSV (stamp,error,dx,dy,dz; metres, "
					"ground-truth frame): where along the run the error is",
					&errorsPath);
			cl.text("plot", "FILE",
					"write a top-down picture (PNG, or JPEG for .jpg) of ground truth and aligned estimate, coloured "
					"by error",
					&plotPath);
			cl.text("loops", "FILE",
					"a run's loop_candidates.csv: label every candidate by the ground truth and print, per stage of "
					"loop detection, how many true and false revisits stopped there, with detection's and "
					"verification's precision and recall (instead of ATE and RPE)",
					&loopsPath);
			cl.text("labels", "FILE",
					"with --loops, also write the candidates with their labels as CSV (true_revisit, distance_m, "
					"angle_deg)",
					&labelsPath);
			if (!cl.parse(argc, argv)) return 0;
			if (!loopsPath.empty() && !estPath.empty())
				throw InputError("", "--loops and --est ask for different evaluations: choose one");
			if (!loopsPath.empty() &&
				(!jsonPath.empty() || !plotPath.empty() || !errorsPath.empty() || o.sim3 || noAlign || o.offset != 0))
				throw InputError("",
								 "--loops takes --gt, --gt-format, --max-diff and --labels only (--json, --plot, "
								 "--errors, --sim3, --no-align and --offset are for --est)");
			if (loopsPath.empty() && estPath.empty())
				throw InputError("", "missing required option --est (or --loops)");
			if (!labelsPath.empty() && loopsPath.empty()) throw InputError("", "--labels needs --loops");
			if (!loopsPath.empty())
			{
				const EGroundTruthFormat format = resolveGroundTruthFormat(gtPath, parseGroundTruthFormat(gtFormat));
				const TTrajectory gt = readGroundTruth(gtPath, format);
				if (gt.empty()) throw InputError(gtPath, "contains no poses");
				TLoopLabelOptions lo;
				lo.maxDiff = o.maxDiff;
				const TLoopLabelReport r = labelLoopCandidates(readLoopCandidatesCsv(loopsPath), gt, lo);
				std::fputs(formatLoopLabelReport(r).c_str(), stdout);
				if (!labelsPath.empty()) writeFileAtomically(labelsPath, formatLabelledLoopCandidatesCsv(r));
				return 0;
			}
			o.align = !noAlign;
			if (noAlign && o.sim3) throw InputError("", "--no-align and --sim3 contradict each other: choose one");
			if (unit != "s" && unit != "f") throw InputError("", "--rpe-unit must be 's' or 'f', got '" + unit + "'");
			o.rpeDeltaInFrames = unit == "f";
			if (!(o.maxDiff > 0)) throw InputError("", "--max-diff must be positive");
			if (!(o.rpeDelta > 0)) throw InputError("", "--rpe-delta must be positive");
			if (o.rpeDeltaInFrames && o.rpeDelta != std::floor(o.rpeDelta))
				throw InputError("", "--rpe-delta counts frames with --rpe-unit f: a whole number, got " +
										 std::to_string(o.rpeDelta));

			const EGroundTruthFormat format = resolveGroundTruthFormat(gtPath, parseGroundTruthFormat(gtFormat));
			if (format == EGroundTruthFormat::Bonn)
				std::fprintf(stderr, "yesslam-eval: note: %s: %s\n", gtPath.c_str(),
							 describeGroundTruthFormat(format).c_str());
			const TTrajectory gt = readGroundTruth(gtPath, format);
			const TTrajectory est = readTumTrajectory(estPath);
			if (gt.empty()) throw InputError(gtPath, "contains no poses");
			if (est.empty()) throw InputError(estPath, "contains no poses");
			const TEvalReport r = evaluateTrajectories(gt, est, o, gtPath, estPath);
			std::fputs(formatEvalKeyValues(r).c_str(), stdout);
			if (!r.hasRpe) std::fprintf(stderr, "yesslam-eval: note: no RPE (%s)\n", r.rpeProblem.c_str());
			if (!jsonPath.empty()) writeFileAtomically(jsonPath, formatEvalJson(r));
			if (!errorsPath.empty()) writeFileAtomically(errorsPath, formatAteErrorsCsv(r.ate));
			if (!plotPath.empty())
				plotAteTopDown(r.ate, gt, plotPath,
							   std::filesystem::path(estPath).filename().string() + " vs " +
								   std::filesystem::path(gtPath).filename().string());
			return 0;
		});
}
