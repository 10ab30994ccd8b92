// Loop candidates labelled by a ground truth (issue 64 item 1): what counts as a true revisit, and
// the precision and recall of detection and verification that the labels add up to.
#include <gtest/gtest.h>
#include <mrpt/core/bits_math.h>

#include "TestUtils.h"
#include "mrpt_yesslam/eval/LoopLabels.h"

using namespace mrpt_yesslam;
using namespace yesslam_test;

TEST(LoopLabels, ARevisitIsNearWithTheSameViewAndARollKeepsTheView)
{
	// The camera at t = 0, and where it stands at later stamps, relative to it in its optical frame
	// (x right, y down, z forward; MRPT's yaw turns about z, pitch about y, roll about x).
	const mrpt::poses::CPose3D start(1, 2, 0.5, 0.3, 0, 0);
	const auto at = [&](double t, const mrpt::poses::CPose3D& relative)
	{ return TStampedPose::fromPose(t, start + relative); };
	const TTrajectory gt{at(0, {}),
						 at(10, {0.2, 0, 0.1, 0, 0, 0}),
						 at(20, {0, 0, 0, 0, 0, mrpt::DEG2RAD(60.0)}),
						 at(30, {0, 0, 0, mrpt::DEG2RAD(60.0), 0, 0}),
						 at(40, {0, 0, 1.5, 0, 0, 0}),
						 at(50, {0, 0, 0, 0, mrpt::DEG2RAD(20.0), 0})};
	const auto row = [](std::size_t q, double tq, const char* stage)
	{
		TLabelledLoopCandidate r;
		r.query = q, r.queryStamp = tq, r.candidate = 0, r.candidateStamp = 0, r.stage = stage;
		return r;
	};
	const std::vector<TLabelledLoopCandidate> rows{row(1, 10, "accepted"),    row(2, 20, "ransac"),
												   row(3, 30, "covisible"),   row(4, 40, "accepted"),
												   row(5, 50, "few_matches"), row(6, 99, "inconsistent")};
	const TLoopLabelReport r = labelLoopCandidates(rows, gt);
	ASSERT_EQ(r.rows.size(), 6u);
	EXPECT_TRUE(r.rows[0].trueRevisit) << "22 cm aside, the same view";
	EXPECT_NEAR(r.rows[0].distance, std::hypot(0.2, 0.1), 1e-9);
	EXPECT_FALSE(r.rows[1].trueRevisit) << "tilted 60 degrees: another view";
	EXPECT_NEAR(r.rows[1].angleDeg, 60, 1e-6);
	EXPECT_TRUE(r.rows[2].trueRevisit) << "turned 60 degrees about the optical axis: the same view";
	EXPECT_NEAR(r.rows[2].angleDeg, 0, 1e-6);
	EXPECT_FALSE(r.rows[3].trueRevisit) << "1.5 m ahead: another place";
	EXPECT_NEAR(r.rows[3].distance, 1.5, 1e-9);
	EXPECT_TRUE(r.rows[4].trueRevisit) << "20 degrees away: the views overlap";
	EXPECT_NEAR(r.rows[4].angleDeg, 20, 1e-6);
	EXPECT_FALSE(r.rows[5].labelled) << "no ground truth at t = 99";
	EXPECT_EQ(r.unlabelled, 1u);
	// Detection: reached verification (accepted, ransac, few_matches); verification: accepted.
	// Recall of detection leaves out what the map already links (covisible): no loop to close.
	EXPECT_EQ(r.trueCandidates, 3u);
	EXPECT_EQ(r.trueLoopCandidates, 2u);
	EXPECT_EQ(r.detected, 4u);
	EXPECT_EQ(r.trueDetected, 2u);
	EXPECT_EQ(r.trueTried, 2u);
	EXPECT_EQ(r.accepted, 2u);
	EXPECT_EQ(r.trueAccepted, 1u);
	const std::string text = formatLoopLabelReport(r);
	EXPECT_NE(text.find("detection_precision: 0.5\n"), std::string::npos) << text;
	EXPECT_NE(text.find("detection_recall: 1\n"), std::string::npos) << text;
	EXPECT_NE(text.find("verification_precision: 0.5\n"), std::string::npos) << text;
	EXPECT_NE(text.find("verification_recall: 0.5\n"), std::string::npos) << text;
	EXPECT_NE(text.find("stage_accepted: 1 true, 1 false\n"), std::string::npos) << text;
}

TEST(LoopLabels, TheCsvReadsBackAndABadOneIsRefusedNamingTheLine)
{
	TempDir d("loop_labels");
	writeText(d / "c.csv",
			  "query,query_stamp,candidate,candidate_stamp,bow_score,loop_score,min_score,stage,matches,inliers\n"
			  "12,10.500000,3,2.250000,0.04000,0.61000,0.40000,ransac,35,9\n");
	const auto rows = readLoopCandidatesCsv(d / "c.csv");
	ASSERT_EQ(rows.size(), 1u);
	EXPECT_EQ(rows[0].query, 12u);
	EXPECT_EQ(rows[0].candidate, 3u);
	EXPECT_DOUBLE_EQ(rows[0].candidateStamp, 2.25);
	EXPECT_EQ(rows[0].stage, "ransac");
	EXPECT_EQ(rows[0].matches, 35u);
	EXPECT_EQ(rows[0].inliers, 9u);
	writeText(d / "bad.csv",
			  "query,query_stamp,candidate,candidate_stamp,bow_score,loop_score,min_score,stage,matches,inliers\n"
			  "12,10.5,3,nan,0.04,0.61,0.4,ransac,35,9\n");
	expectInputError([&] { readLoopCandidatesCsv(d / "bad.csv"); },
					 {"bad.csv", "line 2", "'nan' is not a finite number"});
	writeText(d / "stage.csv",
			  "query,query_stamp,candidate,candidate_stamp,bow_score,loop_score,min_score,stage,matches,inliers\n"
			  "12,10.5,3,2.25,0.04,0.61,0.4,maybe,35,9\n");
	expectInputError([&] { readLoopCandidatesCsv(d / "stage.csv"); }, {"stage.csv", "line 2", "unknown stage 'maybe'"});
	writeText(d / "id.csv",
			  "query,query_stamp,candidate,candidate_stamp,bow_score,loop_score,min_score,stage,matches,inliers\n"
			  "1e30,10.5,3,2.25,0.04,0.61,0.4,ransac,35,9\n");
	expectInputError([&] { readLoopCandidatesCsv(d / "id.csv"); }, {"id.csv", "query '1e30' is not a keyframe id"});
	writeText(d / "other.csv", "stamp,error\n");
	expectInputError([&] { readLoopCandidatesCsv(d / "other.csv"); }, {"other.csv", "not a loop_candidates.csv"});
}
