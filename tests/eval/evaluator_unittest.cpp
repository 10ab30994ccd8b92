// The evaluator against the TUM benchmark tools' own numbers (../shared EXPECTED.md), and on
// trajectories whose true error is known by construction.
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <random>
#include <sstream>

#include "TestUtils.h"
#include "mrpt_yesslam/eval/EvalReport.h"
#include "mrpt_yesslam/eval/TrajectoryEvaluator.h"
#include "mrpt_yesslam/eval/TrajectoryPlot.h"
#include "mrpt_yesslam/util/Error.h"

using namespace mrpt_yesslam;
using namespace yesslam_test;

namespace
{
struct ExpectedRow
{
	std::string est, gt;
	std::vector<std::string> cells;  // every column of the table row
};

// Reads the reference table of EXPECTED.md (computed with TUM's evaluate_ate.py / evaluate_rpe.py).
std::vector<ExpectedRow> readExpected()
{
	std::ifstream f(sharedFile("data/tum_eval_trajectories/EXPECTED.md"));
	std::vector<ExpectedRow> rows;
	std::string line;
	while (std::getline(f, line))
	{
		if (line.rfind("| evo_", 0) != 0) continue;
		ExpectedRow r;
		std::stringstream ss(line.substr(1));
		std::string cell;
		while (std::getline(ss, cell, '|'))
		{
			const auto b = cell.find_first_not_of(' '), e = cell.find_last_not_of(' ');
			r.cells.push_back(b == std::string::npos ? "" : cell.substr(b, e - b + 1));
		}
		if (r.cells.size() < 12) continue;
		r.est = r.cells[0];
		r.gt = r.cells[1];
		rows.push_back(r);
	}
	return rows;
}

TTrajectory shared(const std::string& name)
{
	return readTumTrajectory(sharedFile("data/tum_eval_trajectories/" + name));
}
}  // namespace

TEST(Evaluator, ReproducesEveryTumReferenceRow)
{
	const auto rows = readExpected();
	ASSERT_EQ(rows.size(), 5u) << "EXPECTED.md table not found or changed";
	for (const auto& r : rows)
	{
		SCOPED_TRACE(r.est);
		const TTrajectory gt = shared(r.gt), est = shared(r.est);
		TEvalOptions o;
		const auto ate = computeAte(gt, est, o);
		EXPECT_EQ(ate.stats.n, std::stoul(r.cells[2]));
		EXPECT_NEAR(ate.stats.rmse, std::stod(r.cells[3]), 1e-5);
		EXPECT_NEAR(ate.stats.mean, std::stod(r.cells[4]), 1e-5);
		EXPECT_NEAR(ate.stats.median, std::stod(r.cells[5]), 1e-5);
		EXPECT_NEAR(ate.stats.max, std::stod(r.cells[6]), 1e-5);
		o.sim3 = true;
		const auto sim = computeAte(gt, est, o);
		EXPECT_NEAR(sim.stats.rmse, std::stod(r.cells[7]), 1e-5);
		EXPECT_NEAR(sim.alignment.scale, std::stod(r.cells[8]), 1e-4);
		if (r.cells[9] != "-")
		{
			const auto rpe = computeRpe(gt, est, TEvalOptions{});
			EXPECT_EQ(rpe.pairs, std::stoul(r.cells[9]));
			EXPECT_NEAR(rpe.trans.rmse, std::stod(r.cells[10]), 1e-5);
			EXPECT_NEAR(rpe.rotDeg.rmse, std::stod(r.cells[11]), 1e-4);
		}
	}
}

TEST(Evaluator, KnownRigidMotionAndNoise)
{
	// Ground truth: a helix. Estimate: the same in another frame (rotation + translation) plus a known
	// offset on every other pose, so ATE after alignment is known in closed form.
	TTrajectory gt, est;
	const mrpt::poses::CPose3D T(1.0, -2.0, 0.5, 0.7, -0.2, 0.3);
	for (int i = 0; i < 400; i++)
	{
		const double t = 100.0 + i * 0.05;
		const mrpt::poses::CPose3D p(std::cos(0.05 * i), std::sin(0.05 * i), 0.01 * i, 0.05 * i, 0.0, 0.0);
		gt.push_back(TStampedPose::fromPose(t, p));
		est.push_back(TStampedPose::fromPose(t + 0.003, T + p));
	}
	TEvalOptions o;
	const auto clean = computeAte(gt, est, o);
	EXPECT_EQ(clean.stats.n, 400u);
	EXPECT_LT(clean.stats.rmse, 1e-9);
	// The alignment recovers the inverse of T.
	const auto Tinv = -T;
	EXPECT_NEAR(clean.alignment.t.x(), Tinv.x(), 1e-9);
	const auto rpe = computeRpe(gt, est, o);
	EXPECT_LT(rpe.trans.rmse, 1e-9);
	EXPECT_LT(rpe.rotDeg.rmse, 1e-5);
	// 20 s at 20 Hz, delta 1 s: the partner of poses 0..379 is pose i+20; poses 379..399 all pair
	// with the last pose (the closest to t+1 s), which the TUM tool drops.
	EXPECT_EQ(rpe.pairs, 400u - 21u);

	// Scale the estimate: SE(3) alignment sees an error, Sim(3) removes it and reports the scale.
	TTrajectory scaled = est;
	for (auto& p : scaled)
	{
		p.tx *= 2.5;
		p.ty *= 2.5;
		p.tz *= 2.5;
	}
	EXPECT_GT(computeAte(gt, scaled, o).stats.rmse, 0.1);
	o.sim3 = true;
	const auto sim = computeAte(gt, scaled, o);
	EXPECT_NEAR(sim.alignment.scale, 1 / 2.5, 1e-9);
	EXPECT_LT(sim.stats.rmse, 1e-9);
}

TEST(Evaluator, ErrorsForNoCommonStamps)
{
	const TTrajectory gt = shared("evo_freiburg1_xyz-groundtruth.txt");
	TTrajectory est = shared("evo_fr2_desk_ORB.txt");
	expectInputError([&] { computeAte(gt, est, TEvalOptions{}, "gt.txt", "est.txt"); },
					 {"est.txt", "only 0 of", "need at least 3"});
	expectInputError([&] { computeAte(gt, TTrajectory{}, TEvalOptions{}, "gt.txt", "est.txt"); },
					 {"est.txt", "no poses"});
	// An offset that moves the estimate onto the ground truth's clock makes them match again.
	TEvalOptions o;
	const TTrajectory est1 = shared("evo_freiburg1_xyz-rgbdslam.txt");
	TTrajectory shifted = est1;
	for (auto& p : shifted) p.t -= 1000.0;
	o.offset = 1000.0;
	EXPECT_NEAR(computeAte(gt, shifted, o).stats.rmse, computeAte(gt, est1, TEvalOptions{}).stats.rmse, 1e-12);
}

TEST(Evaluator, DuplicateStampsKeepTheLastPoseLikeADict)
{
	TTrajectory t = {{1.0, 0, 0, 0, 0, 0, 0, 1}, {1.0, 5, 0, 0, 0, 0, 0, 1}, {0.5, 1, 0, 0, 0, 0, 0, 1}};
	const auto u = uniqueSortedByTime(t);
	ASSERT_EQ(u.size(), 2u);
	EXPECT_DOUBLE_EQ(u[0].t, 0.5);
	EXPECT_DOUBLE_EQ(u[1].tx, 5.0);
}

TEST(Evaluator, ReportKeysJsonAndPlot)
{
	const TTrajectory gt = shared("evo_freiburg1_xyz-groundtruth.txt");
	const TTrajectory est = shared("evo_freiburg1_xyz-rgbdslam.txt");
	const auto rep = evaluateTrajectories(gt, est, TEvalOptions{}, "gt", "est");
	const std::string kv = formatEvalKeyValues(rep);
	for (const char* k : {"ate_pairs: 786", "ate_rmse: ", "ate_mean: ", "ate_median: ", "ate_std: ", "ate_min: ",
						  "ate_max: ", "rpe_pairs: 753", "rpe_trans_rmse: ", "rpe_rot_rmse_deg: ", "alignment: se3"})
		EXPECT_NE(kv.find(k), std::string::npos) << k;
	const std::string js = formatEvalJson(rep);
	EXPECT_NE(js.find("\"ate_rmse\": 0.0134"), std::string::npos);
	EXPECT_NE(js.find("\"rotation\": [["), std::string::npos);
	EXPECT_NE(js.find("\"scale\": 1.000000000000"), std::string::npos);

	TempDir d("plot");
	plotAteTopDown(rep.ate, gt, d / "ate.png", "fr1/xyz");
	const cv::Mat img = cv::imread(d / "ate.png", cv::IMREAD_COLOR);
	ASSERT_FALSE(img.empty());
	EXPECT_EQ(img.cols, 1000);
	// The estimate is drawn in colour-map colours (not grey), the ground truth in grey.
	int coloured = 0, grey = 0;
	for (int y = 0; y < img.rows; y++)
		for (int x = 0; x < img.cols; x++)
		{
			const auto p = img.at<cv::Vec3b>(y, x);
			const int mx = std::max({p[0], p[1], p[2]}), mn = std::min({p[0], p[1], p[2]});
			coloured += (mx - mn) > 80;
			grey += (mx - mn) < 10 && mx > 60 && mx < 120;
		}
	EXPECT_GT(coloured, 500);
	EXPECT_GT(grey, 500);
	// Nothing is cut at the picture's edges (issue 18 item 6: the legend was clipped on the right):
	// the outermost columns and rows are background.
	int drawnOnEdge = 0;
	for (const cv::Rect edge :
		 {cv::Rect(0, 0, 2, img.rows), cv::Rect(img.cols - 2, 0, 2, img.rows), cv::Rect(0, img.rows - 2, img.cols, 2)})
	{
		cv::Mat dark;
		cv::inRange(img(edge), cv::Scalar(0, 0, 0), cv::Scalar(230, 230, 230), dark);
		drawnOnEdge += cv::countNonZero(dark);
	}
	EXPECT_EQ(drawnOnEdge, 0);
	// A .jpg name gives a JPEG.
	plotAteTopDown(rep.ate, gt, d / "ate.jpg", "fr1/xyz");
	EXPECT_EQ(readText(d / "ate.jpg").substr(0, 2), std::string("\xFF\xD8"));
}

TEST(Evaluator, JitterIsTheEstimatesOwnFrameToFrameErrorBesideTheSteps)
{
	// The camera moves 2 mm a frame along x; the estimate follows it but swings +-3 mm across (y)
	// every other frame, as a noisy real-sensor estimate does: 6 mm of jitter a frame, where the
	// ATE alone (3 mm) cannot tell a swinging estimate from one offset by a constant bias.
	TTrajectory gt, est;
	for (int i = 0; i < 60; i++)
	{
		TStampedPose g;
		g.t = i / 30.0;
		g.tx = 0.002 * i;
		gt.push_back(g);
		TStampedPose e = g;
		e.ty = (i % 2 ? 0.003 : -0.003);
		est.push_back(e);
	}
	const TEvalReport r = evaluateTrajectories(gt, est, TEvalOptions(), "gt", "est");
	EXPECT_NEAR(r.stepGt.median, 0.002, 1e-9);
	EXPECT_NEAR(r.stepEst.median, std::hypot(0.002, 0.006), 2e-4);
	EXPECT_NEAR(r.jitter.median, 0.006, 2e-4);
	const std::string kv = formatEvalKeyValues(r);
	for (const char* k : {"step_est_median: ", "step_gt_median: ", "jitter_median: ", "jitter_rmse: "})
		EXPECT_NE(kv.find(k), std::string::npos) << k;
	// An estimate that follows the truth exactly has none.
	EXPECT_NEAR(evaluateTrajectories(gt, gt, TEvalOptions(), "gt", "gt").jitter.max, 0.0, 1e-12);
}

TEST(Evaluator, WithoutAlignmentTheEstimateIsComparedAsItIs)
{
	// An estimate 1 m off along x, otherwise exact: aligned (the TUM tools) it has no error; compared
	// as it is (yesslam-eval --no-align: a run localised in a saved map's frame) it is 1 m off.
	TTrajectory gt, est;
	for (int i = 0; i < 30; i++)
	{
		TStampedPose g;
		g.t = i / 30.0;
		g.tx = 0.01 * i;
		g.ty = 0.002 * i * i;
		gt.push_back(g);
		g.tx += 1.0;
		est.push_back(g);
	}
	TEvalOptions o;
	EXPECT_LT(evaluateTrajectories(gt, est, o, "gt", "est").ate.stats.rmse, 1e-9);
	o.align = false;
	const TEvalReport r = evaluateTrajectories(gt, est, o, "gt", "est");
	EXPECT_NEAR(r.ate.stats.rmse, 1.0, 1e-9);
	EXPECT_NE(formatEvalKeyValues(r).find("alignment: none"), std::string::npos);
}

TEST(Evaluator, TheErrorsTableTellsWhereAlongTheRunTheErrorIs)
{
	// Exact but for frame 12, 3 cm off along y: compared as it is, the table has one row per pair in
	// time order, zero everywhere but that frame's row, which holds the offset.
	TTrajectory gt, est;
	for (int i = 0; i < 20; i++)
	{
		TStampedPose g;
		g.t = 100 + i / 30.0;
		g.tx = 0.01 * i;
		gt.push_back(g);
		if (i == 12) g.ty += 0.03;
		est.push_back(g);
	}
	TEvalOptions o;
	o.align = false;
	std::istringstream csv(formatAteErrorsCsv(evaluateTrajectories(gt, est, o, "gt", "est").ate));
	std::string line;
	std::getline(csv, line);
	EXPECT_EQ(line, "stamp,error,dx,dy,dz");
	int rows = 0;
	while (std::getline(csv, line))
	{
		double t = 0, e = 0, dx = 0, dy = 0, dz = 0;
		ASSERT_EQ(std::sscanf(line.c_str(), "%lf,%lf,%lf,%lf,%lf", &t, &e, &dx, &dy, &dz), 5) << line;
		EXPECT_NEAR(t, gt[static_cast<std::size_t>(rows)].t, 1e-6);
		EXPECT_NEAR(e, rows == 12 ? 0.03 : 0.0, 1e-6) << line;
		EXPECT_NEAR(dy, rows == 12 ? 0.03 : 0.0, 1e-6) << line;
		EXPECT_NEAR(dx, 0.0, 1e-6);
		rows++;
	}
	EXPECT_EQ(rows, 20);
}
