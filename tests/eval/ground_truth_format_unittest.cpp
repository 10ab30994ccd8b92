// --gt-format bonn: the Bonn RGB-D Dynamic dataset's ground truth (motion-capture marker poses)
// brought into the camera frame, checked on a real run over the dataset's frames.
// Data: ../shared/data/bonn_crowd_dev (Bonn RGB-D Dynamic Dataset, Palazzolo et al., IROS 2019;
// research data, used here for testing only as its SOURCE.md allows, never copied).
#include <gtest/gtest.h>

#include <filesystem>

#include "TestUtils.h"
#include "mrpt_yesslam/eval/EvalReport.h"
#include "mrpt_yesslam/eval/GroundTruthFormat.h"
#include "mrpt_yesslam/jobs/SlamJob.h"

using namespace mrpt_yesslam;
using namespace yesslam_test;

TEST(GroundTruthFormat, BonnMarkerPosesBecomeTheCameraPosesARealRunMeasures)
{
	// The people-free opening of the real crowd slice (60 frames, 2 s of panning). Our estimate is
	// of the camera; compared with the markers' poses, RPE sees the marker frame's rotation against
	// the camera's (measured 19.0 deg per second); compared with the camera poses the conversion
	// gives, only the estimate's own error remains (measured 1.1). Of the other readings of the
	// dataset's formula, T_m inverted gives 20.2 and the markers merely rotated by T_ros 32.3.
	const std::string dir =
		std::filesystem::path(sharedFile("data/bonn_crowd_dev/groundtruth.txt")).parent_path().string();
	TempDir d("gt_format_bonn");
	TSlamJobOptions o;
	o.input = dir;
	o.outDir = d.path();
	o.maxFrames = 60;
	o.slam.detector.backend = "none";
	o.slam.system.parallel = false;
	o.slam.dense.enabled = false;
	o.slam.loop.detection.enabled = false;
	// Issue 42 item 4: the folder is recognised as Bonn's without --gt-format (the default, auto).
	const TSlamJobSummary s = runSlamJob(o);
	EXPECT_EQ(s.groundTruthFormat, EGroundTruthFormat::Bonn);
	ASSERT_TRUE(s.evaluated) << s.evalProblem;
	ASSERT_TRUE(s.eval.hasRpe) << s.eval.rpeProblem;

	const TTrajectory markers = readGroundTruth(dir + "/groundtruth.txt", EGroundTruthFormat::Tum);
	const TEvalReport raw = evaluateTrajectories(markers, readTumTrajectory(d / "trajectory.txt"), TEvalOptions(),
												 "markers", "trajectory.txt");
	ASSERT_TRUE(raw.hasRpe);
	EXPECT_LT(s.eval.rpe.rotDeg.rmse, 0.35 * raw.rpe.rotDeg.rmse)
		<< "bonn " << s.eval.rpe.rotDeg.rmse << " deg, raw " << raw.rpe.rotDeg.rmse;
	EXPECT_LT(s.eval.rpe.rotDeg.rmse, 2.0);

	// The conversion is rigid and per pose: distances between camera positions differ from the
	// markers' only by the 2 cm lever arm, and stamps are kept.
	const TTrajectory cams = bonnMarkersToCamera(markers);
	ASSERT_EQ(cams.size(), markers.size());
	for (std::size_t i = 0; i < markers.size(); i++)
	{
		EXPECT_EQ(cams[i].t, markers[i].t);
		const Eigen::Vector3d a(markers[i].tx, markers[i].ty, markers[i].tz),
			b(markers.front().tx, markers.front().ty, markers.front().tz);
		const Eigen::Vector3d ca(cams[i].tx, cams[i].ty, cams[i].tz),
			cb(cams.front().tx, cams.front().ty, cams.front().tz);
		EXPECT_NEAR((ca - cb).norm(), (a - b).norm(), 0.04);
	}
}

TEST(GroundTruthFormat, AnUnknownFormatIsAOneLineError)
{
	EXPECT_EQ(parseGroundTruthFormat("BONN"), EGroundTruthFormat::Bonn);
	EXPECT_EQ(parseGroundTruthFormat("tum"), EGroundTruthFormat::Tum);
	expectInputError([] { parseGroundTruthFormat("kitti"); }, {"--gt-format", "'kitti'", "tum", "bonn"});
	// auto: the dataset's folders (rgbd_bonn_<sequence>) and files named for it are Bonn's, others TUM's;
	// a format given is kept.
	EXPECT_EQ(parseGroundTruthFormat("Auto"), EGroundTruthFormat::Auto);
	EXPECT_EQ(resolveGroundTruthFormat("/data/rgbd_bonn_crowd/groundtruth.txt", EGroundTruthFormat::Auto),
			  EGroundTruthFormat::Bonn);
	EXPECT_EQ(resolveGroundTruthFormat("rec/rgbd_bonn_crowd2_groundtruth.txt", EGroundTruthFormat::Auto),
			  EGroundTruthFormat::Bonn);
	EXPECT_EQ(
		resolveGroundTruthFormat("/data/rgbd_dataset_freiburg3_walking_xyz/groundtruth.txt", EGroundTruthFormat::Auto),
		EGroundTruthFormat::Tum);
	EXPECT_EQ(resolveGroundTruthFormat("/data/rgbd_bonn_crowd/groundtruth.txt", EGroundTruthFormat::Tum),
			  EGroundTruthFormat::Tum);
}
