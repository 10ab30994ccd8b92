// Tracking on real sensor data: the 9 consecutive TUM fr1_desk frames in ../shared (Kinect depth,
// motion-capture ground truth; CC BY 4.0, see its SOURCE.md), and recovery after a frame with
// nothing to track.
#include <gtest/gtest.h>
#include <mrpt/poses/CPose3DQuat.h>
#include <mrpt/poses/Lie/SO.h>

#include <random>
#include <set>

#include <opencv2/imgproc.hpp>

#include "TestUtils.h"
#include "mrpt_yesslam/eval/TrajectoryEvaluator.h"
#include "mrpt_yesslam/io/RgbdObservation.h"
#include "mrpt_yesslam/system/CYesSlamSystem.h"

using namespace mrpt_yesslam;
using namespace yesslam_test;

namespace
{
TYesSlamOptions realOptions()
{
	TYesSlamOptions o;
	o.detector.backend = "none";
	o.system.parallel = false;
	o.input.camera = "fr1";
	return o;
}

// The 9 real fr1_desk frames, in order.
std::vector<mrpt::obs::CObservation3DRangeScan::Ptr> deskFrames()
{
	auto src = openInputSource(sharedFile("data/tum_fr1_desk_9frames"), realOptions().input);
	std::vector<mrpt::obs::CObservation3DRangeScan::Ptr> frames;
	while (auto obs = src->next()) frames.push_back(obs);
	return frames;
}

// A tracker on `map` (keyframe 0 the reference) that has seen `last` (the motion measured on them)
// tracks `next` from scratch (not tracked, no pose).
CTracker::TResult trackAfter(CSparseMap& map, const CTracker::TOptions& o,
							 const std::vector<std::shared_ptr<TFrame>>& last, TFrame& next)
{
	CTracker tracker(o, map, 1.2, CGeometricDynamicCheck::TOptions());
	tracker.setReferenceKeyFrame(0);
	for (const auto& f : last) tracker.setLastFrame(f);
	next.tracked = false;
	next.pose = mrpt::poses::CPose3D();
	return tracker.track(next);
}
}  // namespace

TEST(Tracker, RealFr1DeskFramesMatchMotionCapture)
{
	const std::string dir = sharedFile("data/tum_fr1_desk_9frames");
	const TTrajectory gt = readTumTrajectory(sharedFile("data/tum_fr1_desk_9frames/groundtruth.txt"));
	const TYesSlamOptions o = realOptions();
	CYesSlamSystem sys(o);
	auto src = openInputSource(dir, o.input);
	std::size_t n = 0;
	while (auto obs = src->next())
	{
		const TFrameReport r = sys.processFrame(*obs);
		EXPECT_TRUE(r.tracked) << "frame " << n;
		if (n > 0)
		{
			EXPECT_GT(r.inliers, 100u) << "frame " << n;
		}
		n++;
	}
	ASSERT_EQ(n, 9u);
	const TAteResult ate = computeAte(gt, sys.trajectory(), TEvalOptions());
	EXPECT_EQ(ate.stats.n, 9u);
	// fr1_desk moves ~0.4 m/s: 9 frames span ~10 cm; the mocap itself is good to a few mm.
	EXPECT_LT(ate.stats.rmse, 0.01);
}

TEST(Tracker, BeyondFarDepthAKeypointEntersThePoseSolveWithoutItsDepth)
{
	// [Camera] farDepth: a keypoint whose depth reads beyond it enters the pose solve by its pixel
	// alone (no depth residual: sigmaZ 0), a nearer one with its depth; 0 keeps every depth.
	TFrame f;
	TLocalMapPoints pts;
	std::vector<TMatch> m;
	for (const double z : {1.0, 2.9, 3.1, 5.0})
	{
		f.features.keypoints.push_back(cv::KeyPoint(320.f, 240.f, 31.f));
		f.features.depth.push_back(static_cast<float>(z));
		pts.positions.push_back({0, 0, z});
		m.push_back({m.size(), m.size(), 0});
	}
	TDepthNoise noise;
	noise.farDepth = 3.0;
	const auto obs = makePoseObservations(f, m, pts, 1.2, noise);
	ASSERT_EQ(obs.size(), 4u);
	EXPECT_DOUBLE_EQ(obs[0].sigmaZ, noise.sigma(1.0));
	EXPECT_DOUBLE_EQ(obs[1].sigmaZ, noise.sigma(f.features.depth[1]));
	EXPECT_EQ(obs[2].sigmaZ, 0.0);
	EXPECT_EQ(obs[3].sigmaZ, 0.0);
	// The depth itself stays known (the mover check sizes and groups keypoints by it).
	EXPECT_DOUBLE_EQ(obs[2].depth, f.features.depth[2]);
	EXPECT_DOUBLE_EQ(obs[3].depth, 5.0);
	noise.farDepth = 0;
	for (const auto& o : makePoseObservations(f, m, pts, 1.2, noise)) EXPECT_GT(o.sigmaZ, 0.0);
}

TEST(Tracker, TheLocalMapIsSearchedWithTheViewChecksUnlessTheyAreOff)
{
	// Issue 27: [Tracking] viewChecks reaches the local-map search (the search itself is tested in
	// OrbMatcher.ViewChecksSearchAPointOnlyWhereItsPyramidAndItsViewsReach). The real fr1 frames
	// are tracked with and without; the checks change what is matched, so the poses differ, and
	// both runs stay within a centimetre of the motion capture.
	const TTrajectory gt = readTumTrajectory(sharedFile("data/tum_fr1_desk_9frames/groundtruth.txt"));
	const auto run = [&](bool viewChecks)
	{
		TYesSlamOptions o = realOptions();
		o.tracking.viewChecks = viewChecks;
		CYesSlamSystem sys(o);
		for (const auto& obs : deskFrames()) EXPECT_TRUE(sys.processFrame(*obs).tracked);
		EXPECT_LT(computeAte(gt, sys.trajectory(), TEvalOptions()).stats.rmse, 0.01) << "viewChecks " << viewChecks;
		return sys.trajectory();
	};
	EXPECT_TRUE(TYesSlamOptions().tracking.viewChecks) << "on by default";
	const TTrajectory on = run(true), off = run(false);
	ASSERT_EQ(on.size(), off.size());
	double largest = 0;
	for (std::size_t i = 0; i < on.size(); i++)
		largest = std::max(largest, std::hypot(on[i].tx - off[i].tx, on[i].ty - off[i].ty, on[i].tz - off[i].tz));
	EXPECT_GT(largest, 1e-5) << "the option did not reach the search";
}

TEST(Tracker, RecoversAfterAFrameWithoutFeatures)
{
	const std::string dir = sharedFile("data/tum_fr1_desk_9frames");
	const TYesSlamOptions o = realOptions();
	CYesSlamSystem sys(o);
	auto src = openInputSource(dir, o.input);
	std::vector<mrpt::obs::CObservation3DRangeScan::Ptr> frames;
	while (auto obs = src->next()) frames.push_back(obs);
	ASSERT_EQ(frames.size(), 9u);
	for (int i = 0; i < 4; i++) EXPECT_TRUE(sys.processFrame(*frames[static_cast<std::size_t>(i)]).tracked);
	// A black frame with no depth (a covered lens): no crash, not tracked, a pose all the same.
	const cv::Mat black(480, 640, CV_8UC3, cv::Scalar::all(0)), noDepth(480, 640, CV_32F, cv::Scalar(0));
	const TFrameReport lost =
		sys.processFrame(black, noDepth, observationTime(*frames[4]) - 0.001, frames[4]->cameraParamsIntensity);
	EXPECT_FALSE(lost.tracked);
	for (std::size_t i = 4; i < 9; i++) EXPECT_TRUE(sys.processFrame(*frames[i]).tracked) << i;
	EXPECT_EQ(sys.trajectory().size(), 10u);
	EXPECT_EQ(sys.stats().lostFrames, 1u);
}

// A person filling the whole image (a detection box over every pixel): every feature is masked, the
// frame cannot be tracked, and the system goes on with the motion model; the held box (holdFrames)
// masks the next frame too; then tracking resumes on the real frames.
TEST(Tracker, KeepsGoingWhenAPersonCoversTheWholeImage)
{
	const std::string dir = sharedFile("data/tum_fr1_desk_9frames");
	const TTrajectory gt = readTumTrajectory(sharedFile("data/tum_fr1_desk_9frames/groundtruth.txt"));
	TYesSlamOptions o = realOptions();
	auto src = openInputSource(dir, o.input);
	std::vector<mrpt::obs::CObservation3DRangeScan::Ptr> frames;
	while (auto obs = src->next()) frames.push_back(obs);
	ASSERT_EQ(frames.size(), 9u);
	TempDir d("cover");
	char line[128];
	std::snprintf(line, sizeof(line), "%.6f 0 0.95 0 0 640 480\n", observationTime(*frames[4]));
	writeText(d / "detections.txt", std::string("# timestamp class_id score x y w h\n") + line);
	o.detector.backend = "file";
	o.detector.file = d / "detections.txt";
	o.masker.holdFrames = 1;
	o.masker.method = "box";  // the whole image is masked (a fill would keep what lies behind the seed's depth)
	CYesSlamSystem sys(o);
	for (std::size_t i = 0; i < 9; i++)
	{
		const TFrameReport r = sys.processFrame(*frames[i]);
		if (i == 4 || i == 5)
			EXPECT_FALSE(r.tracked) << "frame " << i << " has no static feature";
		else
			EXPECT_TRUE(r.tracked) << "frame " << i;
	}
	EXPECT_EQ(sys.trajectory().size(), 9u);
	EXPECT_EQ(sys.stats().lostFrames, 2u);
	// The two blind frames got the constant-velocity pose: the whole run stays within a few cm.
	EXPECT_LT(computeAte(gt, sys.trajectory(), TEvalOptions()).stats.rmse, 0.03);
}

// Issue 14 (blinded camera): frames with no usable view are lost, and their poses continue the
// last measured motion, damped, instead of stopping dead while the camera moves on (fr1_desk moves
// about 0.4 m/s: two held frames are a centimetre or more off).
TEST(Tracker, LostFramesContinueTheLastMotion)
{
	const TTrajectory gt = readTumTrajectory(sharedFile("data/tum_fr1_desk_9frames/groundtruth.txt"));
	const auto frames = deskFrames();
	ASSERT_EQ(frames.size(), 9u);
	const cv::Mat black(480, 640, CV_8UC3, cv::Scalar::all(0)), noDepth(480, 640, CV_32F, cv::Scalar(0));
	const auto worstError = [&](double damping)
	{
		TYesSlamOptions o = realOptions();
		o.tracking.lostDamping = damping;
		CYesSlamSystem sys(o);
		for (std::size_t i = 0; i < frames.size(); i++)
			if (i == 4 || i == 5)
				EXPECT_FALSE(
					sys.processFrame(black, noDepth, observationTime(*frames[i]), frames[i]->cameraParamsIntensity)
						.tracked);
			else
				EXPECT_TRUE(sys.processFrame(*frames[i]).tracked) << i;
		EXPECT_EQ(sys.stats().lostFrames, 2u);
		// The poses as the run wrote them while it went (smoothedTrajectory() re-places lost frames
		// between the tracked ones afterwards), and the frames after: tracking resumes from either guess.
		EXPECT_LT(computeAte(gt, sys.smoothedTrajectory(), TEvalOptions()).stats.max, 0.008) << "damping " << damping;
		return computeAte(gt, sys.onlineTrajectory(), TEvalOptions()).stats.max;
	};
	const double coasting = worstError(0.9), held = worstError(0.0);
	EXPECT_GT(held, 0.008);
	EXPECT_LT(coasting, 0.6 * held);
}

// A lost frame coasts on the mean motion of the last tracked frames (lostVelocityFrames), not on
// the last step alone: the step just before a person blinds the camera is the one the person
// already pulls on (a camera standing still on walking_static coasted 56 mm off on such a step).
TEST(Tracker, ALostFrameCoastsOnTheMeanOfTheLastMotionsNotOnALastJerk)
{
	std::mt19937 rng(5);
	std::vector<mrpt::math::TPoint3D> world;
	for (int i = 0; i < 60; i++) world.emplace_back(-1.0 + 0.035 * i, -0.5 + 0.017 * (i % 7), 2.5 + 0.01 * (i % 5));
	const auto coastedX = [&](std::size_t window)
	{
		CSparseMap map;
		const auto first = observeWorld(0, {}, world, std::vector<TPointId>(world.size(), -1), rng);
		map.addKeyFrame(first, 10.0);
		CTracker::TOptions to;
		to.lostVelocityFrames = window;
		CTracker tracker(to, map, 1.2, CGeometricDynamicCheck::TOptions());
		tracker.setReferenceKeyFrame(0);
		// 1 cm per frame along x, then a 4 cm jerk on the last tracked frame.
		double x = 0;
		for (std::size_t k = 0; k < 6; k++)
		{
			auto f = std::make_shared<TFrame>();
			f->id = k;
			f->camera = first->camera;
			f->tracked = true;
			x += k == 0 ? 0.0 : (k == 5 ? 0.04 : 0.01);
			f->pose = mrpt::poses::CPose3D(x, 0, 0, 0, 0, 0);
			tracker.setLastFrame(f);
		}
		TFrame lost;  // nothing to match: the frame is lost
		lost.id = 6;
		lost.camera = first->camera;
		const auto r = tracker.track(lost);
		EXPECT_FALSE(r.ok);
		EXPECT_FALSE(lost.tracked);
		return lost.pose.x();
	};
	EXPECT_NEAR(coastedX(3), 0.08 + (0.01 + 0.01 + 0.04) / 3, 1e-6);  // the mean of the last three steps
	EXPECT_NEAR(coastedX(1), 0.08 + 0.04, 1e-6);                      // the last step alone (the old behaviour)
}

// Issue 40 (e): the velocity that undoes the rolling shutter is the motion over the time the last
// frames span. Live input drops frames: a camera at a steady 0.3 m/s whose frame 3 never came took
// a 2 cm step over 67 ms, which is no faster; averaging the steps and dividing by the last interval
// alone made it 0.4 m/s. And after a loss the velocity is measured anew: motions from before it
// (here the other way) are not averaged with those after.
TEST(Tracker, TheShutterVelocityIsTheMotionOverTheTimeAndStartsAnewAfterALoss)
{
	CSparseMap map;
	CTracker::TOptions to;
	to.lostVelocityFrames = 3;
	CTracker tracker(to, map, 1.2, CGeometricDynamicCheck::TOptions());
	std::size_t id = 0;
	const auto frameAt = [&](double t, double x, bool tracked)
	{
		auto f = std::make_shared<TFrame>();
		f->id = id++;
		f->timestamp = t;
		f->tracked = tracked;
		f->pose = mrpt::poses::CPose3D(x, 0, 0, 0, 0, 0);
		tracker.setLastFrame(f);
	};
	const double dt = 1.0 / 30, speed = 0.3, readout = 0.028;
	for (int k : {0, 1, 2, 4, 5}) frameAt(k * dt, speed * k * dt, true);  // frame 3 dropped
	auto m = tracker.motionOver(readout);
	ASSERT_TRUE(m.has_value());
	EXPECT_NEAR(m->x(), speed * readout, 1e-9);
	// Lost (a person fills the view), then found again moving the other way.
	frameAt(6 * dt, speed * 6 * dt, false);
	EXPECT_FALSE(tracker.motionOver(readout).has_value());
	frameAt(7 * dt, 0.2, true);
	frameAt(8 * dt, 0.2 - speed * dt, true);
	m = tracker.motionOver(readout);
	ASSERT_TRUE(m.has_value());
	EXPECT_NEAR(m->x(), -speed * readout, 1e-9);
}

// Issue 40 (review): the prediction spans the frame intervals since the last frame. Live input
// and the TUM recordings drop frames (the fr3 sequences have steps of two and three intervals).
// A camera panning at 0.9 rad/s whose next three frames never came has turned four steps (0.12 rad,
// about 65 pixels at the image's edge): predicted one step on, every point lay beyond the
// projection search and the frame was found again only by brute-force matching and PnP; a frame
// lost there coasted one step where the camera had moved four.
TEST(Tracker, AFrameAfterDroppedOnesIsPredictedOverItsIntervals)
{
	std::mt19937 rng(7);
	std::vector<mrpt::math::TPoint3D> world;
	std::uniform_real_distribution<double> ux(-3.0, 3.0), uy(-1.0, 1.0), uz(2.8, 3.2);
	for (int i = 0; i < 400; i++) world.emplace_back(ux(rng), uy(rng), uz(rng));
	const double dt = 1.0 / 30, turn = 0.03;  // rad per frame
	const auto poseAt = [&](std::size_t k)
	{ return mrpt::poses::CPose3D(0, 0, 0, 0, turn * static_cast<double>(k), 0); };
	const auto first = observeWorld(0, poseAt(0), world, std::vector<TPointId>(world.size(), -1), rng);
	// Every frame sees each point with the same descriptor (the map's and the last frame's).
	const auto frameAt = [&](std::size_t k, bool features)
	{
		auto f = observeWorld(k, poseAt(k), world, std::vector<TPointId>(world.size(), -1), rng);
		f->features.descriptors = first->features.descriptors.clone();
		f->timestamp = static_cast<double>(k) * dt;
		if (!features) f->features = TFeatures();
		return f;
	};
	const auto next = [&](std::size_t dropped, bool features)
	{
		CSparseMap map;
		map.addKeyFrame(first, 10.0);
		auto f = frameAt(4 + dropped, features);
		const CTracker::TResult r = trackAfter(
			map, CTracker::TOptions(), {frameAt(0, true), frameAt(1, true), frameAt(2, true), frameAt(3, true)}, *f);
		return std::make_pair(r, f->pose);
	};
	// Without dropped frames the one-step prediction is right.
	const auto [steady, steadyPose] = next(0, true);
	EXPECT_TRUE(steady.ok);
	EXPECT_FALSE(steady.recoveredByPnP);
	EXPECT_GT(steady.motionMatches, 200u);
	// Three dropped: found by projection around the prediction, as if none had been.
	const auto [afterGap, gapPose] = next(3, true);
	EXPECT_TRUE(afterGap.ok);
	EXPECT_FALSE(afterGap.recoveredByPnP) << "the prediction was a step behind: brute force found the frame";
	EXPECT_GT(afterGap.motionMatches, 200u);
	EXPECT_LT((gapPose - poseAt(7)).norm(), 1e-3);
	// Lost there (nothing to match): the camera coasts the four steps.
	const auto [lost, lostPose] = next(3, false);
	EXPECT_FALSE(lost.ok);
	const double coastedDeg =
		mrpt::RAD2DEG(mrpt::poses::Lie::SO<3>::log((lostPose - poseAt(7)).getRotationMatrix()).norm());
	EXPECT_LT(coastedDeg, 0.5) << "coasted " << coastedDeg << " degrees short of the camera";
}

// Issue 40 (review): when the local map does not confirm a frame, tracking keeps the solution
// against the last frame's points (step 3). Those are the few map points it matched and many
// temporary points back-projected from the last frame's depth, and a person walking beside the
// camera, whom no detector reported, fills the last frame with the latter. Here 150 of them move
// 5 cm a frame against the camera's 1 cm: together they say the camera moved 6 cm, a step no
// hand-held camera makes, on 150 inliers, which counted as strong evidence and went unchecked.
// Counted by the map points it matched (none agree), the solution is weak and is refused: the frame
// coasts on the motion model.
TEST(Tracker, ASolutionRestingOnTheLastFramesTemporaryPointsIsJudgedByItsMapPoints)
{
	std::mt19937 rng(11);
	std::uniform_real_distribution<double> u(-1.0, 1.0);
	std::vector<mrpt::math::TPoint3D> wall, person;  // the wall in the world; the person in the first camera's frame
	for (int i = 0; i < 15; i++) wall.emplace_back(2.0 * u(rng), 1.4 * u(rng), 4.0 + 0.3 * u(rng));
	for (int i = 0; i < 150; i++) person.emplace_back(0.6 * u(rng), 0.45 * u(rng), 2.0 + 0.05 * u(rng));
	const double dt = 1.0 / 30, step = 0.01, personStep = -0.05;  // m per frame along x
	const auto cameraAt = [&](std::size_t k)
	{ return mrpt::poses::CPose3D(step * static_cast<double>(k), 0, 0, 0, 0, 0); };
	const auto wallFrame = observeWorld(0, cameraAt(0), wall, std::vector<TPointId>(wall.size(), -1), rng);
	const auto personFrame = observeWorld(0, cameraAt(0), person, std::vector<TPointId>(person.size(), -1), rng);
	CSparseMap map;
	map.addKeyFrame(wallFrame, 10.0);  // the person came after the first keyframe
	// The wall's map point ids, by position.
	const TLocalMapPoints kfPts = map.keyFramePoints(0);
	std::vector<TPointId> wallIds(wall.size(), -1);
	for (std::size_t j = 0; j < wall.size(); j++)
		for (std::size_t q = 0; q < kfPts.ids.size(); q++)
			if (std::abs(kfPts.positions[q].x - wall[j].x) + std::abs(kfPts.positions[q].y - wall[j].y) +
					std::abs(kfPts.positions[q].z - wall[j].z) <
				1e-6)
				wallIds[j] = kfPts.ids[q];
	ASSERT_EQ(std::count(wallIds.begin(), wallIds.end(), -1), 0);
	// Frame k: the wall (with its map points when `matched`) and the person, who has walked k steps.
	const auto frameAt = [&](std::size_t k, bool matched)
	{
		std::vector<mrpt::math::TPoint3D> p;
		for (const auto& q : person) p.emplace_back(q.x + personStep * static_cast<double>(k), q.y, q.z);
		auto f = observeWorld(k, cameraAt(k), wall, matched ? wallIds : std::vector<TPointId>(wall.size(), -1), rng);
		const auto g = observeWorld(k, cameraAt(k), p, std::vector<TPointId>(p.size(), -1), rng);
		f->features.descriptors = wallFrame->features.descriptors.clone();
		for (std::size_t i = 0; i < g->size(); i++)
		{
			f->features.keypoints.push_back(g->features.keypoints[i]);
			f->features.depth.push_back(g->features.depth[i]);
			f->features.dynamic.push_back(false);
			f->colors.push_back(g->colors[i]);
			f->mapPoints.push_back(-1);
		}
		f->features.descriptors.push_back(personFrame->features.descriptors);
		f->timestamp = static_cast<double>(k) * dt;
		return f;
	};
	auto f = frameAt(5, false);
	const CTracker::TResult r = trackAfter(
		map, CTracker::TOptions(), {frameAt(1, true), frameAt(2, true), frameAt(3, true), frameAt(4, true)}, *f);
	EXPECT_GE(r.motionMatches, 100u) << "the test needs the person matched against the last frame";
	EXPECT_FALSE(r.ok) << "taken " << (f->pose - cameraAt(5)).norm() * 100 << " cm off the camera";
	EXPECT_TRUE(r.implausible);
	EXPECT_LT((f->pose - cameraAt(5)).norm(), 0.01) << "coasted on the motion model";
}

// Issue 62 (item 4): at the map's edge the local map cannot confirm a frame (few of its points
// are in view), and step 3 keeps the solution against the last frame's points. Counted by its map
// points alone nearly every such solution was weak, so a real jerk there was refused and, with
// step 1 gone after a refusal, tracking stayed lost until the map came back into view. Here 15
// mapped points and 150 static ones the map has not reached yet: the camera jerks 8 cm and 8
// degrees beyond the motion model. The map points agree with the solution (the people check's
// counterpart above: none do when a person carries it), so all its certain inliers count.
TEST(Tracker, AtTheMapsEdgeAJerkIsJudgedByAllTheCertainInliersTheMapPointsAgreeWith)
{
	std::mt19937 rng(12);
	std::uniform_real_distribution<double> u(-1.0, 1.0);
	std::vector<mrpt::math::TPoint3D> mapped, unmapped;
	for (int i = 0; i < 15; i++) mapped.emplace_back(-0.5 + 0.3 * u(rng), 0.9 * u(rng), 3.0 + 0.3 * u(rng));
	for (int i = 0; i < 150; i++) unmapped.emplace_back(0.6 * u(rng), 0.9 * u(rng), 3.0 + 0.3 * u(rng));
	const double dt = 1.0 / 30, step = 0.01;
	const mrpt::poses::CPose3D jerk(0.08, 0, 0, 0, mrpt::DEG2RAD(8.0), 0);
	const auto cameraAt = [&](std::size_t k)
	{
		return mrpt::poses::CPose3D(step * static_cast<double>(k), 0, 0, 0, 0, 0) +
			   (k >= 5 ? jerk : mrpt::poses::CPose3D());
	};
	std::vector<mrpt::math::TPoint3D> all = mapped;
	all.insert(all.end(), unmapped.begin(), unmapped.end());
	const auto first = observeWorld(0, cameraAt(0), mapped, std::vector<TPointId>(mapped.size(), -1), rng);
	const auto everything = observeWorld(0, cameraAt(0), all, std::vector<TPointId>(all.size(), -1), rng);
	CSparseMap map;
	map.addKeyFrame(first, 10.0);
	const TLocalMapPoints kfPts = map.keyFramePoints(0);
	ASSERT_EQ(kfPts.ids.size(), mapped.size());
	std::vector<TPointId> ids(all.size(), -1);
	for (std::size_t j = 0; j < mapped.size(); j++)
		for (std::size_t q = 0; q < kfPts.ids.size(); q++)
			if ((kfPts.positions[q] - mapped[j]).norm() < 1e-6) ids[j] = kfPts.ids[q];
	ASSERT_EQ(std::count(ids.begin(), ids.begin() + 15, -1), 0);
	// Each frame sees every point with the same descriptor: the mapped ones as the keyframe's.
	cv::Mat descriptors = everything->features.descriptors.clone();
	first->features.descriptors.copyTo(descriptors.rowRange(0, 15));
	const auto frameAt = [&](std::size_t k, bool matched)
	{
		auto f = observeWorld(k, cameraAt(k), all, matched ? ids : std::vector<TPointId>(all.size(), -1), rng);
		f->features.descriptors = descriptors.clone();
		f->timestamp = static_cast<double>(k) * dt;
		return f;
	};
	auto f = frameAt(5, false);
	const CTracker::TResult r = trackAfter(
		map, CTracker::TOptions(), {frameAt(1, true), frameAt(2, true), frameAt(3, true), frameAt(4, true)}, *f);
	EXPECT_TRUE(r.ok) << "refused " << (f->pose - cameraAt(5)).norm() * 100 << " cm off the camera";
	EXPECT_FALSE(r.implausible);
	EXPECT_LT(r.localMatches, CTracker::TOptions().minTrackedInliers)
		<< "the test needs the local map unable to confirm the frame";
	EXPECT_LT((f->pose - cameraAt(5)).norm(), 0.005);
}

// Issue 62 (item 4): a relocalisation on enough inliers (relocInliers, ORB-SLAM2's 50) is a pose
// of its own, not held to the prediction tracking just failed to confirm. Every solution is made
// weak here (weakInliers beyond any count) and the camera jerks 8 cm and 8 degrees: the local map
// refuses the jerk, and relocalisation finds the camera on all 400 map points.
TEST(Tracker, ARelocalisationOnEnoughInliersIsNotHeldToTheFailedPrediction)
{
	std::mt19937 rng(13);
	std::vector<mrpt::math::TPoint3D> world;
	std::uniform_real_distribution<double> ux(-1.5, 1.5), uy(-1.0, 1.0), uz(2.8, 3.2);
	for (int i = 0; i < 400; i++) world.emplace_back(ux(rng), uy(rng), uz(rng));
	const double dt = 1.0 / 30;
	const mrpt::poses::CPose3D jerk(0.08, 0, 0, 0, mrpt::DEG2RAD(8.0), 0);
	const auto cameraAt = [&](std::size_t k)
	{
		return mrpt::poses::CPose3D(0.01 * static_cast<double>(k), 0, 0, 0, 0, 0) +
			   (k >= 5 ? jerk : mrpt::poses::CPose3D());
	};
	const auto first = observeWorld(0, cameraAt(0), world, std::vector<TPointId>(world.size(), -1), rng);
	const auto frameAt = [&](std::size_t k)
	{
		auto f = observeWorld(k, cameraAt(k), world, std::vector<TPointId>(world.size(), -1), rng);
		f->features.descriptors = first->features.descriptors.clone();
		f->timestamp = static_cast<double>(k) * dt;
		return f;
	};
	const auto run = [&](std::size_t relocInliers)
	{
		CSparseMap map;
		map.addKeyFrame(first, 10.0);
		CTracker::TOptions o;
		o.weakInliers = 100000;
		o.relocInliers = relocInliers;
		auto f = frameAt(5);
		const CTracker::TResult r = trackAfter(map, o, {frameAt(1), frameAt(2), frameAt(3), frameAt(4)}, *f);
		return std::make_pair(r, (f->pose - cameraAt(5)).norm());
	};
	const auto [found, off] = run(CTracker::TOptions().relocInliers);
	EXPECT_TRUE(found.ok);
	EXPECT_TRUE(found.relocalised);
	EXPECT_LT(off, 0.005);
	// Held to the prediction as any other solution (relocInliers 0): refused, the frame coasts.
	const auto [held, heldOff] = run(0);
	EXPECT_FALSE(held.ok);
	EXPECT_TRUE(held.implausible);
	EXPECT_GT(heldOff, 0.05);
}

// Issue 62 (item 4): the departures a weak solution may make grow with the frame intervals since
// the motion was last measured: three dropped frames are four intervals in which the camera may
// have sped up. Every solution weak and relocalisation held to the prediction too (relocInliers
// 0): the camera, 1 cm a frame, is 8 cm beyond the prediction after the gap (20 cm allowed over
// four intervals); the same 8 cm after one interval is refused.
TEST(Tracker, TheDeparturesAllowedGrowWithTheIntervalsSinceTheLastFrame)
{
	std::mt19937 rng(14);
	std::vector<mrpt::math::TPoint3D> world;
	std::uniform_real_distribution<double> ux(-1.5, 1.5), uy(-1.0, 1.0), uz(2.8, 3.2);
	for (int i = 0; i < 400; i++) world.emplace_back(ux(rng), uy(rng), uz(rng));
	const double dt = 1.0 / 30;
	const auto steady = [&](std::size_t k)
	{ return mrpt::poses::CPose3D(0.01 * static_cast<double>(k), 0, 0, 0, 0, 0); };
	const auto first = observeWorld(0, steady(0), world, std::vector<TPointId>(world.size(), -1), rng);
	const auto frameAt = [&](std::size_t k, const mrpt::poses::CPose3D& pose)
	{
		auto f = observeWorld(k, pose, world, std::vector<TPointId>(world.size(), -1), rng);
		f->features.descriptors = first->features.descriptors.clone();
		f->timestamp = static_cast<double>(k) * dt;
		return f;
	};
	const auto run = [&](std::size_t dropped)
	{
		CSparseMap map;
		map.addKeyFrame(first, 10.0);
		CTracker::TOptions o;
		o.weakInliers = 100000;
		o.relocInliers = 0;
		o.motionPriorSigma = 0;  // the solve itself, not pulled toward the prediction it is judged by
		const std::size_t k = 5 + dropped;
		const mrpt::poses::CPose3D truth(0.01 * static_cast<double>(k) + 0.08, 0, 0, 0, 0, 0);
		auto f = frameAt(k, truth);
		const CTracker::TResult r = trackAfter(
			map, o, {frameAt(1, steady(1)), frameAt(2, steady(2)), frameAt(3, steady(3)), frameAt(4, steady(4))}, *f);
		return std::make_pair(r, (f->pose - truth).norm());
	};
	const auto [afterGap, offAfterGap] = run(3);
	EXPECT_TRUE(afterGap.ok);
	EXPECT_FALSE(afterGap.implausible);
	EXPECT_LT(offAfterGap, 0.005);
	const auto [next, offNext] = run(0);
	EXPECT_FALSE(next.ok);
	EXPECT_TRUE(next.implausible);
}

namespace
{
// A textured board (a "person") painted into real fr1_desk frames: a plane parallel to the first
// camera's image plane at depth z0, `w` x `h` m, centred at (cx + offset, cy) in the first camera's
// frame, seen from camera k (pose T0k relative to the first). Colour and depth are overwritten where
// the board is in front.
void paintBoard(cv::Mat& bgr, cv::Mat& depth, const mrpt::img::TCamera& K, const mrpt::poses::CPose3D& T0k,
				const cv::Mat& texture, double cx, double cy, double z0, double w, double h)
{
	const auto R = T0k.getRotationMatrix();
	for (int v = 0; v < bgr.rows; v++)
		for (int u = 0; u < bgr.cols; u++)
		{
			const double d[3] = {(u - K.cx()) / K.fx(), (v - K.cy()) / K.fy(), 1.0};
			double rd[3];
			for (int i = 0; i < 3; i++) rd[i] = R(i, 0) * d[0] + R(i, 1) * d[1] + R(i, 2) * d[2];
			if (std::abs(rd[2]) < 1e-9) continue;
			const double lambda = (z0 - T0k.z()) / rd[2];  // depth along camera k's axis (d.z = 1)
			if (lambda <= 0) continue;
			const double X = T0k.x() + lambda * rd[0] - (cx - w / 2), Y = T0k.y() + lambda * rd[1] - (cy - h / 2);
			if (X < 0 || Y < 0 || X >= w || Y >= h) continue;
			float& z = depth.at<float>(v, u);
			if (z > 0 && z < lambda) continue;
			z = static_cast<float>(lambda);
			bgr.at<cv::Vec3b>(v, u) =
				texture.at<cv::Vec3b>(static_cast<int>(Y / h * texture.rows), static_cast<int>(X / w * texture.cols));
		}
}

// The 9 real desk frames with a board standing 0.55 m in front of the first camera (0.14 x 0.22 m,
// centred at x = 0.05 in that camera's frame), painted at each frame's ground-truth pose.
struct TDeskWithBoard
{
	static constexpr double z0 = 0.55, w = 0.14, h = 0.22, cx = 0.05, cy = 0.0;
	std::vector<mrpt::obs::CObservation3DRangeScan::Ptr> frames = deskFrames();
	TTrajectory gt = readTumTrajectory(sharedFile("data/tum_fr1_desk_9frames/groundtruth.txt"));
	cv::Mat texture = cv::Mat(60, 40, CV_8UC3);  // not braces: cv::Mat's initializer-list constructor
	mrpt::poses::CPose3D Tw0;

	TDeskWithBoard()
	{
		cv::RNG rng(5);
		rng.fill(texture, cv::RNG::UNIFORM, 0, 256);
		cv::resize(texture, texture, {160, 240}, 0, 0, cv::INTER_NEAREST);  // 4x4-pixel blocks: corners ORB finds
		Tw0 = poseAt(observationTime(*frames.at(0)));
	}
	mrpt::poses::CPose3D poseAt(double t) const
	{
		const TStampedPose* best = &gt.front();
		for (const auto& p : gt)
			if (std::abs(p.t - t) < std::abs(best->t - t)) best = &p;
		return mrpt::poses::CPose3D(mrpt::poses::CPose3DQuat(
			best->tx, best->ty, best->tz, mrpt::math::CQuaternionDouble(best->qw, best->qx, best->qy, best->qz)));
	}
	/** Frame k's colour and depth with the board moved `offset` m along x from its place. */
	std::pair<cv::Mat, cv::Mat> frame(std::size_t k, double offset) const
	{
		cv::Mat bgr = frames[k]->intensityImage.asCvMat<cv::Mat>(mrpt::img::DEEP_COPY),
				depth = depthInMetres(*frames[k]);
		paintBoard(bgr, depth, frames[k]->cameraParamsIntensity, poseAt(observationTime(*frames[k])) - Tw0, texture,
				   cx + offset, cy, z0, w, h);
		return {bgr, depth};
	}
	bool onBoard(const mrpt::math::TPoint3D& p) const
	{
		return std::abs(p.z - z0) < 0.05 && std::abs(p.x - cx) < w / 2 + 0.02 && std::abs(p.y - cy) < h / 2 + 0.02;
	}
};
}  // namespace

// Issue 14: map points on a person who stood still and then walks away must not stay in the map
// (ghosts that later pull tracking). A board stands still in front of the desk for 5 real frames
// (the camera moves, so it is mapped like the desk), then moves 15 cm per frame out of its place:
// the space where its points were is now seen through (the desk behind is measured there), and
// the points are erased. With both the see-through test and the mover check off they stay.
TEST(Tracker, MapPointsOfAPersonWhoWalksAwayAreErased)
{
	const TDeskWithBoard scene;
	const auto& frames = scene.frames;
	ASSERT_EQ(frames.size(), 9u);
	const auto run = [&](bool checks, std::size_t& before)
	{
		TYesSlamOptions o = realOptions();
		// Grown-up points are never judged by ORB-SLAM2's young-point culling; with 9 frames these
		// are all young, so that culling is off here, and two seen-through frames suffice (5 frames
		// follow the move).
		o.mapping.cullFoundRatio = 0;
		o.mapping.cullMinObservations = 0;
		o.tracking.seeThroughFrames = 2;
		if (!checks)
		{
			o.tracking.seeThroughFrames = 0;
			o.geometric.movers = false;
		}
		CYesSlamSystem sys(o);
		// The still board's points (ids seen on it before it moves) that are still in the map.
		std::set<TPointId> still;
		const auto stillLeft = [&]
		{
			std::size_t n = 0;
			for (const auto& p : sys.map().points()) n += still.count(p.id);
			return n;
		};
		for (std::size_t k = 0; k < frames.size(); k++)
		{
			const auto [bgr, depth] =
				scene.frame(k, k < 4 ? 0.0 : 0.15 * static_cast<double>(k - 3));  // walks away along x
			EXPECT_TRUE(
				sys.processFrame(bgr, depth, observationTime(*frames[k]), frames[k]->cameraParamsIntensity).tracked)
				<< k;
			if (k == 3)
				for (const auto& p : sys.map().points())
					if (scene.onBoard(p.position)) still.insert(p.id);
		}
		before = still.size();
		return stillLeft();
	};
	std::size_t beforeOn = 0, beforeOff = 0;
	const std::size_t afterOn = run(true, beforeOn), afterOff = run(false, beforeOff);
	EXPECT_GE(beforeOn, 15u) << "the still board should be mapped";
	// Measured: 26 % remain (where the desk behind has too few keypoints to see through), 100 % without.
	EXPECT_LE(afterOn * 3, beforeOn) << "at most a third of its points may remain once it has left";
	EXPECT_GE(afterOff * 10, beforeOff * 9) << "without the checks they stay";
}

// Issue 40 (review): the mover check's regions (where it last saw something move; keypoints there
// are uncertain for a few frames) aged only on frames the local map confirmed. After a loss they
// were as fresh as before it, though the mover had gone on walking. The board walks away as above
// (2 cm a frame, which the check finds moving), then six frames show nothing (lost): the regions
// from before the loss are gone after them.
TEST(Tracker, MoverRegionsAgeWhileTrackingIsLost)
{
	const TDeskWithBoard scene;
	const auto& frames = scene.frames;
	ASSERT_EQ(frames.size(), 9u);
	CYesSlamSystem sys(realOptions());
	std::size_t withRegions = 0;
	for (std::size_t k = 0; k < frames.size(); k++)
	{
		const auto [bgr, depth] =
			scene.frame(k, k < 4 ? 0.0 : 0.02 * static_cast<double>(k - 3));  // walks away along x
		EXPECT_TRUE(sys.processFrame(bgr, depth, observationTime(*frames[k]), frames[k]->cameraParamsIntensity).tracked)
			<< k;
		if (!sys.tracker().moverRegions().empty()) withRegions++;
	}
	ASSERT_FALSE(sys.tracker().moverRegions().empty())
		<< "the test needs the walking board found moving (" << withRegions << " frames had regions)";
	const cv::Mat black(480, 640, CV_8UC3, cv::Scalar::all(0)), noDepth(480, 640, CV_32F, cv::Scalar(0));
	const double t8 = observationTime(*frames[8]), dt = t8 - observationTime(*frames[7]);
	for (int k = 1; k <= 6; k++)
		EXPECT_FALSE(sys.processFrame(black, noDepth, t8 + k * dt, frames[8]->cameraParamsIntensity).tracked);
	EXPECT_TRUE(sys.tracker().moverRegions().empty())
		<< sys.tracker().moverRegions().size() << " regions from before the loss are still held";
}

TEST(Tracker, AVelocityMeasuredAcrossALoopCorrectionHoldsNoneOfIt)
{
	// A correction moves the map between two tracked frames. The next frame is tracked in the
	// corrected map; its velocity is measured against the last frame's pose in that same map, not
	// the pose the last frame had before (that difference would hold the whole correction, and a
	// lost frame right after would coast on it). Issue 28 item 1 (b).
	const auto frames = deskFrames();
	ASSERT_EQ(frames.size(), 9u);
	CYesSlamSystem sys(realOptions());
	std::vector<mrpt::poses::CPose3D> poses;
	sys.setFrameCallback([&](const TFrame& f) { poses.push_back(f.pose); });
	for (std::size_t i = 0; i < 5; i++) ASSERT_TRUE(sys.processFrame(*frames[i]).tracked) << i;
	const mrpt::poses::CPose3D T(0.5, 0.1, -0.2, mrpt::DEG2RAD(20.0), 0, mrpt::DEG2RAD(5.0));
	std::map<TKeyFrameId, mrpt::poses::CPose3D> corrected;
	for (const auto& k : sys.map().keyFramePoses())
		if (!k.bad) corrected[k.id] = T + k.pose;
	sys.mutableMap().applyCorrection(corrected);
	ASSERT_TRUE(sys.processFrame(*frames[5]).tracked);
	// The last tracked frame is in the corrected map.
	EXPECT_LT((poses[5].asVectorVal() - (T + poses[4]).asVectorVal()).head<3>().norm(), 0.05);
	// A covered lens: the lost frame coasts on the last motions (fr1_desk moves about 1.5 cm a frame).
	const cv::Mat black(480, 640, CV_8UC3, cv::Scalar::all(0)), noDepth(480, 640, CV_32F, cv::Scalar(0));
	EXPECT_FALSE(
		sys.processFrame(black, noDepth, observationTime(*frames[6]), frames[6]->cameraParamsIntensity).tracked);
	ASSERT_EQ(poses.size(), 7u);
	const mrpt::poses::CPose3D step = poses[6] - poses[5];
	EXPECT_LT(step.norm(), 0.05) << "coasted " << step.norm() << " m from the last tracked pose";
	EXPECT_LT(mrpt::poses::Lie::SO<3>::log(step.getRotationMatrix()).norm(), mrpt::DEG2RAD(3.0));
	// And tracking goes on in the corrected map.
	for (std::size_t i = 7; i < 9; i++) EXPECT_TRUE(sys.processFrame(*frames[i]).tracked) << i;
}

// Issue 39 item 1: no pose without evidence. After 8 real fr1/desk frames, the ninth shows what the
// first did, through a small window (the rest covered, as by a person filling the view): its few
// inliers place the camera where it was 0.27 s before, about 10 cm behind where it can be 33 ms
// after the eighth. That weak solution is refused: the frame is not tracked and coasts on the
// measured motion, and the run says so. A strong solution as far away is taken (relocalisation).
namespace
{
// The first real fr1/desk frame seen through a 150 x 120 window, the rest black and without depth.
std::pair<cv::Mat, cv::Mat> firstFrameThroughAWindow(const mrpt::obs::CObservation3DRangeScan& first)
{
	cv::Mat bgr = first.intensityImage.asCvMatRef().clone(), depth = depthInMetres(first);
	const cv::Rect window(250, 170, 150, 120);
	cv::Mat keepMask = cv::Mat::zeros(bgr.size(), CV_8U);
	keepMask(window).setTo(255);
	bgr.setTo(cv::Scalar::all(0), ~keepMask);
	depth.setTo(0, ~keepMask);
	return {bgr, depth};
}

// How far the system's last online pose (at time t) is from the truth, in the map's frame (the
// first frame defines it).
double offTheTruth(const CYesSlamSystem& sys, const TTrajectory& gt, double t0, double t)
{
	const auto nearest = [&](double s)
	{
		std::size_t g = 0;
		for (std::size_t k = 0; k < gt.size(); k++)
			if (std::abs(gt[k].t - s) < std::abs(gt[g].t - s)) g = k;
		return gt[g].asPose();
	};
	const mrpt::poses::CPose3D truth = nearest(t) - nearest(t0);
	return (sys.onlineTrajectory().back().asPose() - truth).norm();
}
}  // namespace

TEST(Tracker, AWeakSolutionFarFromTheMotionModelIsNotTracked)
{
	const TTrajectory gt = readTumTrajectory(sharedFile("data/tum_fr1_desk_9frames/groundtruth.txt"));
	const auto frames = deskFrames();
	ASSERT_EQ(frames.size(), 9u);
	const auto [bgr, depth] = firstFrameThroughAWindow(*frames[0]);
	const double t0 = observationTime(*frames[0]), t8 = observationTime(*frames[8]);
	const auto run = [&](std::size_t weakInliers, const cv::Mat& img, const cv::Mat& d)
	{
		TYesSlamOptions o = realOptions();
		o.tracking.weakInliers = weakInliers;
		CYesSlamSystem sys(o);
		for (std::size_t i = 0; i < 8; i++) EXPECT_TRUE(sys.processFrame(*frames[i]).tracked) << i;
		const TFrameReport r = sys.processFrame(img, d, t8, frames[8]->cameraParamsIntensity);
		return std::make_tuple(r, offTheTruth(sys, gt, t0, t8), sys.stats());
	};
	const auto [without, offWithout, statsWithout] = run(0, bgr, depth);
	EXPECT_TRUE(without.tracked) << "the window alone is enough to track (" << without.inliers << " inliers)";
	EXPECT_LT(without.inliers, TYesSlamOptions().tracking.weakInliers) << "the test needs a weak solution";
	EXPECT_GT(offWithout, 0.06) << "it places the camera where frame 0 was";
	const auto [with, offWith, statsWith] = run(TYesSlamOptions().tracking.weakInliers, bgr, depth);
	EXPECT_FALSE(with.tracked);
	EXPECT_TRUE(with.poseRefused);
	EXPECT_EQ(statsWith.refusedPoses, 1u);
	EXPECT_LT(offWith, 0.02) << "coasted on the measured motion";
	// The whole first frame: a strong solution, taken however far it is (the camera was carried
	// back, or relocalisation found it).
	const auto [strong, offStrong, statsStrong] =
		run(TYesSlamOptions().tracking.weakInliers, frames[0]->intensityImage.asCvMatRef().clone(),
			depthInMetres(*frames[0]));
	EXPECT_TRUE(strong.tracked);
	EXPECT_FALSE(strong.poseRefused);
	EXPECT_GT(offStrong, 0.06);
}

// The same after a loss (priorLostFrames): the person who blinded the camera for a frame still
// covers most of the view in the next, and what shows through the window is the place frame 0
// saw. The coasted prediction judges that weak solution as a measured one would, with twice the
// tolerance; before, a frame after a lost one took any solution unchecked (real Bonn crowd slice:
// frame 170, two frames after a loss, tracked on 35 inliers 86 mm off).
TEST(Tracker, AfterALostFrameAWeakSolutionFarFromTheCoastedPredictionIsNotTracked)
{
	const TTrajectory gt = readTumTrajectory(sharedFile("data/tum_fr1_desk_9frames/groundtruth.txt"));
	const auto frames = deskFrames();
	ASSERT_EQ(frames.size(), 9u);
	const auto [bgr, depth] = firstFrameThroughAWindow(*frames[0]);
	const cv::Mat black(480, 640, CV_8UC3, cv::Scalar::all(0)), noDepth(480, 640, CV_32F, cv::Scalar(0));
	const double t0 = observationTime(*frames[0]), t8 = observationTime(*frames[8]),
				 t9 = t8 + (t8 - observationTime(*frames[7]));
	const auto run = [&](std::size_t priorLostFrames)
	{
		TYesSlamOptions o = realOptions();
		o.tracking.priorLostFrames = priorLostFrames;
		CYesSlamSystem sys(o);
		for (std::size_t i = 0; i < 8; i++) EXPECT_TRUE(sys.processFrame(*frames[i]).tracked) << i;
		EXPECT_FALSE(sys.processFrame(black, noDepth, t8, frames[8]->cameraParamsIntensity).tracked);
		const TFrameReport r = sys.processFrame(bgr, depth, t9, frames[8]->cameraParamsIntensity);
		// Against the truth at t8: the 9 frames end there, and the coasted pose is one step (1-2 cm
		// on fr1/desk) further on.
		return std::make_tuple(r, offTheTruth(sys, gt, t0, t8), sys.stats());
	};
	const auto [unchecked, offUnchecked, statsUnchecked] = run(0);
	EXPECT_TRUE(unchecked.tracked) << "without the coasted prior the weak solution is taken";
	EXPECT_LT(unchecked.inliers, TYesSlamOptions().tracking.weakInliers) << "the test needs a weak solution";
	EXPECT_GT(offUnchecked, 0.06) << "it places the camera where frame 0 was";
	const auto [checked, offChecked, statsChecked] = run(TYesSlamOptions().tracking.priorLostFrames);
	EXPECT_FALSE(checked.tracked);
	EXPECT_TRUE(checked.poseRefused);
	EXPECT_EQ(statsChecked.refusedPoses, 1u);
	EXPECT_EQ(statsChecked.lostFrames, 2u);
	EXPECT_LT(offChecked, 0.03) << "coasted on: one more step from the last tracked frame";
	// A refused frame is a lost frame too: the next frame's weak solution is judged the same way
	// (a person moving with the camera is there for several frames).
	TYesSlamOptions o = realOptions();
	CYesSlamSystem sys(o);
	for (std::size_t i = 0; i < 8; i++) EXPECT_TRUE(sys.processFrame(*frames[i]).tracked) << i;
	const TFrameReport first = sys.processFrame(bgr, depth, t8, frames[8]->cameraParamsIntensity);
	const TFrameReport second = sys.processFrame(bgr, depth, t9, frames[8]->cameraParamsIntensity);
	EXPECT_TRUE(first.poseRefused);
	EXPECT_TRUE(second.poseRefused);
	EXPECT_FALSE(second.tracked);
	EXPECT_EQ(sys.stats().refusedPoses, 2u);
}
