// CFrameRecords: the trajectories written after the run. Each frame hangs from the keyframe it was
// tracked against (trajectory.txt: carried by its final pose); mapping moves keyframes differently,
// and in trajectory_smoothed.txt ([Output] correctionWindow) the correction is averaged over
// neighbouring frames of one correction generation and applied to the pose tracking measured.
#include <gtest/gtest.h>

#include <cmath>

#include "mrpt_yesslam/system/CFrameRecords.h"

using namespace mrpt_yesslam;

namespace
{
// Frame k of a 30 Hz run with the pose tracking measured for it (tracked) or coasted it on.
CFrameRecords::TRecord record(int k, const mrpt::poses::CPose3D& online, bool tracked = true)
{
	CFrameRecords::TRecord r;
	r.t = 0.033 * k;
	r.tracked = tracked;
	r.hasPose = true;
	r.online = online;
	r.measured = online;
	return r;
}
// Frame k of a camera moving 3 mm a frame along x.
mrpt::poses::CPose3D alongX(int k)
{
	return mrpt::poses::CPose3D(0.003 * k, 0, 0, 0, 0, 0);
}

// 40 frames moving 3 mm a frame along x and turning 0.01 rad a frame, tracked exactly (online = truth). Frames 0-19
// were tracked before a loop correction (generation 1), frames 20-39 after it (generation 2). Every 10 frames two
// keyframes; frames hang from them alternately (the reference keyframe switching). Mapping then moved the keyframes:
// those of generation 1 by the loop's 10 cm in y, and every keyframe by another +-2 mm in y and +-0.5 mrad in yaw,
// alternately (what two local BAs left between neighbours). Corrections act in the world frame: final = correction +
// tracked.
struct TScene
{
	CFrameRecords records;
	std::map<TKeyFrameId, mrpt::poses::CPose3D> finalKeyFrames;
	std::vector<mrpt::poses::CPose3D> truth;
	explicit TScene(int window) : records(false, window)
	{
		for (int k = 0; k < 40; k++) truth.emplace_back(0.003 * k, 0, 0, 0.01 * k, 0, 0);
		for (int s = 0; s < 4; s++)
			for (int ab = 0; ab < 2; ab++)
			{
				const auto id = static_cast<TKeyFrameId>(2 * s + ab);
				const mrpt::poses::CPose3D correction(0, (s < 2 ? 0.1 : 0.0) + (ab == 0 ? 0.002 : -0.002), 0,
													  ab == 0 ? 0.0005 : -0.0005, 0, 0);
				finalKeyFrames[id] = correction + truth[static_cast<std::size_t>(10 * s + 5 * ab)];
			}
		for (int k = 0; k < 40; k++)
		{
			CFrameRecords::TRecord r = record(k, truth[static_cast<std::size_t>(k)]);
			const int s = k / 10, ab = k % 2;
			const auto id = static_cast<TKeyFrameId>(2 * s + ab);
			// Anchored as tracking saw the keyframe then: at its uncorrected pose.
			r.anchor = TAnchor{id, r.online - truth[static_cast<std::size_t>(10 * s + 5 * ab)]};
			r.generation = k < 20 ? 1 : 2;
			records.add(r, TFrameLogRow());
		}
	}
	TTrajectory trajectory() const
	{
		return records.smoothed([this] { return finalKeyFrames; });
	}
};

// How far the estimate's step from frame k to k+1 is from the true step (position, metres).
double stepError(const TTrajectory& t, std::size_t k)
{
	const mrpt::poses::CPose3D trueStep =
		mrpt::poses::CPose3D(0.003 * static_cast<double>(k + 1), 0, 0, 0.01 * static_cast<double>(k + 1), 0, 0) -
		mrpt::poses::CPose3D(0.003 * static_cast<double>(k), 0, 0, 0.01 * static_cast<double>(k), 0, 0);
	const auto e = (t[k + 1].asPose() - t[k].asPose()) - trueStep;
	return std::hypot(e.x(), e.y(), e.z());
}
}  // namespace

TEST(FrameRecords, ConsecutiveFramesOnDifferentKeyFramesStepAsTheCameraDid)
{
	const TTrajectory plain = TScene(0).trajectory(), smooth = TScene(3).trajectory();
	ASSERT_EQ(plain.size(), 40u);
	ASSERT_EQ(smooth.size(), 40u);
	double worstPlain = 0, worstSmooth = 0;
	for (std::size_t k = 0; k + 1 < 40; k++)
	{
		if (k == 19) continue;  // the loop correction's step, below
		worstPlain = std::max(worstPlain, stepError(plain, k));
		worstSmooth = std::max(worstSmooth, stepError(smooth, k));
	}
	EXPECT_GT(worstPlain, 0.0039) << "each frame following its own keyframe steps by their corrections' difference";
	EXPECT_LT(worstSmooth, 0.0012);
	// The trajectory still follows what mapping moved the frames by, on average.
	for (std::size_t k = 3; k < 37; k++) EXPECT_NEAR(smooth[k].ty, k < 20 ? 0.1 : 0.0, 0.001) << k;
}

TEST(FrameRecords, CorrectionsAreNotAveragedAcrossALoopCorrection)
{
	// Frames 19 and 20 were tracked in two different maps (before and after the loop's 10 cm): each
	// keeps its own generation's correction.
	const TTrajectory t = TScene(3).trajectory();
	ASSERT_EQ(t.size(), 40u);
	for (std::size_t k = 16; k < 24; k++) EXPECT_NEAR(t[k].ty, k < 20 ? 0.1 : 0.0, 0.0015) << k;
}

TEST(FrameRecords, AFramePinnedToItsKeyFrameKeepsTheKeyFramesPose)
{
	// [System] keyFrameFramePose = keyframe: the frame a keyframe was made of is that keyframe's
	// final pose, whatever its neighbours' corrections.
	CFrameRecords records(false, 3);
	const std::map<TKeyFrameId, mrpt::poses::CPose3D> finals{{0, mrpt::poses::CPose3D(0, 0.01, 0, 0, 0, 0)},
															 {1, mrpt::poses::CPose3D(0.015, -0.01, 0, 0.002, 0, 0)}};
	for (int k = 0; k < 10; k++)
	{
		CFrameRecords::TRecord r = record(k, alongX(k));
		r.anchor = TAnchor{TKeyFrameId(0), r.online};
		records.add(r, TFrameLogRow());
	}
	TFrameLogRow row;
	row.frame = 10;
	CFrameRecords::TRecord r = record(10, mrpt::poses::CPose3D(0.015, 0, 0, 0, 0, 0));
	r.anchor = TAnchor{TKeyFrameId(0), r.online};
	records.add(r, row);
	records.markKeyFrame(10, TAnchor{TKeyFrameId(1), mrpt::poses::CPose3D()});
	const TTrajectory t = records.smoothed([&] { return finals; });
	ASSERT_EQ(t.size(), 11u);
	const auto& k = finals.at(1);
	EXPECT_NEAR(t[10].tx, k.x(), 1e-12);
	EXPECT_NEAR(t[10].ty, k.y(), 1e-12);
	EXPECT_NEAR((t[10].asPose() - k).asVectorVal().norm(), 0.0, 1e-9);
	// Its neighbours are still averaged (their own keyframe moved 1 cm in y).
	EXPECT_NEAR(t[5].ty, 0.01, 1e-9);
}

TEST(FrameRecords, FramesCoastedAtTheEndMoveWithTheLastTrackedOne)
{
	// A run that ends while lost: the coasted frames keep their step from the last tracked frame,
	// not their keyframe's own, unaveraged correction (a jump of what the average took away).
	TScene scene(3);
	for (int k = 40; k < 43; k++)
	{
		CFrameRecords::TRecord r = record(k, mrpt::poses::CPose3D(0.003 * k, 0, 0, 0.01 * k, 0, 0), false);  // coasted
		r.anchor = TAnchor{TKeyFrameId(7), r.online - scene.truth[35]};
		r.generation = 2;
		scene.records.add(r, TFrameLogRow());
	}
	const TTrajectory t = scene.trajectory();
	ASSERT_EQ(t.size(), 43u);
	for (std::size_t k = 38; k < 42; k++) EXPECT_LT(stepError(t, k), 1e-9 + (k == 38 ? 0.0012 : 0.0)) << k;
}

TEST(FrameRecords, AFrameWhoseKeyFrameIsGoneLendsItsFallbackToNoNeighbour)
{
	// Every frame hangs from keyframe 0, which mapping moved 1 cm in y, except frame 5, whose
	// keyframe the final map no longer has: its pose falls back to its relative pose, metres from
	// the path. Its neighbours' corrections stay their own keyframe's.
	CFrameRecords records(false, 3);
	const std::map<TKeyFrameId, mrpt::poses::CPose3D> finals{{0, mrpt::poses::CPose3D(0, 0.01, 0, 0, 0, 0)}};
	for (int k = 0; k < 11; k++)
	{
		CFrameRecords::TRecord r = record(k, alongX(k));
		r.anchor = k == 5 ? TAnchor{TKeyFrameId(9), mrpt::poses::CPose3D(1, 2, 0, 0, 0, 0)}
						  : TAnchor{TKeyFrameId(0), r.online};
		records.add(r, TFrameLogRow());
	}
	const TTrajectory t = records.smoothed([&] { return finals; });
	ASSERT_EQ(t.size(), 11u);
	for (std::size_t k = 0; k < 11; k++)
	{
		if (k == 5) continue;
		EXPECT_NEAR(t[k].ty, 0.01, 1e-9) << k;
	}
	EXPECT_NEAR(t[5].tx, 1.0, 1e-12);  // it keeps its fallback
	EXPECT_NEAR(t[5].ty, 2.0, 1e-12);
}

TEST(FrameRecords, FramesCoastedAfterAPinnedFrameKeepTheirOwnPoses)
{
	// Coasting after a frame pinned to its keyframe (it is that keyframe's pose, not averaged):
	// the coasted frames hang from their own keyframe as recorded, not from an earlier frame's
	// averaged correction.
	CFrameRecords records(false, 3);
	const std::map<TKeyFrameId, mrpt::poses::CPose3D> finals{{0, mrpt::poses::CPose3D(0, 0.01, 0, 0, 0, 0)},
															 {1, mrpt::poses::CPose3D(0.015, -0.01, 0, 0, 0, 0)}};
	for (int k = 0; k < 9; k++)
	{
		CFrameRecords::TRecord r = record(k, alongX(k), k < 6);
		if (k < 5)
			r.anchor = TAnchor{TKeyFrameId(0), r.online};
		else if (k == 5)
			r.pinTo(TAnchor{TKeyFrameId(1), mrpt::poses::CPose3D()});
		else
			r.anchor = TAnchor{TKeyFrameId(1), mrpt::poses::CPose3D(0.003 * (k - 5), 0, 0, 0, 0, 0)};
		records.add(r, TFrameLogRow());
	}
	const TTrajectory t = records.smoothed([&] { return finals; });
	ASSERT_EQ(t.size(), 9u);
	EXPECT_NEAR(t[5].ty, -0.01, 1e-12);
	for (std::size_t k = 6; k < 9; k++)
	{
		EXPECT_NEAR(t[k].tx, 0.015 + 0.003 * static_cast<double>(k - 5), 1e-12) << k;
		EXPECT_NEAR(t[k].ty, -0.01, 1e-12) << k;
	}
}

namespace
{
// A camera that speeds up and turns back along x (a parabola in time) while drifting in y, each
// tracked pose off by its own solve's noise (+-1.5 mm, alternating in sign frame to frame, as the
// real slice's poses zig-zag), its orientation exact. All frames hang from keyframe 0, which
// mapping left where it was: only the smoothing acts.
struct TNoisyRun
{
	std::vector<mrpt::poses::CPose3D> truth;
	TTrajectory written;
	// Frames [lostFrom, lostTo) are coasted (tracking lost them) on a path of their own. Frame
	// `relocalisedAt` was relocalised: the frames before it had drifted 3 cm.
	explicit TNoisyRun(int window, int frames = 60, int newGenerationAt = -1, int lostFrom = -1, int lostTo = -1,
					   int relocalisedAt = -1)
	{
		CFrameRecords records(false, 0, window);
		for (int k = 0; k < frames; k++)
		{
			const double t = k / 30.0;
			truth.emplace_back(0.2 * t - 0.3 * t * t, 0.05 * t, 0, 0.2 * t, 0, 0);
			const double noise = (k % 2 ? 0.0015 : -0.0015) * (k % 3 ? 1.0 : 0.5);
			const double drift = k < relocalisedAt ? -0.03 : 0.0;
			const mrpt::poses::CPose3D measured(truth.back().x() + noise + drift, truth.back().y() - noise,
												truth.back().z() + noise, 0.2 * t, 0, 0);
			CFrameRecords::TRecord r = record(k, measured, k < lostFrom || k >= lostTo);
			r.t = t;
			r.anchor = TAnchor{TKeyFrameId(0), measured};
			r.generation = newGenerationAt >= 0 && k >= newGenerationAt ? 2 : 1;
			TFrameLogRow row;
			row.relocalised = k == relocalisedAt;
			records.add(r, row);
		}
		written = records.smoothed(
			[] {
				return std::map<TKeyFrameId, mrpt::poses::CPose3D>{{0, mrpt::poses::CPose3D()}};
			});
	}
	double positionError(std::size_t k) const
	{
		return std::hypot(written[k].tx - truth[k].x(), written[k].ty - truth[k].y(), written[k].tz - truth[k].z());
	}
};
}  // namespace

TEST(FrameRecords, TheWrittenPositionsAreFreedOfTheSingleFrameNoiseAndKeepTheCamerasAcceleration)
{
	const TNoisyRun plain(0), smooth(8);
	ASSERT_EQ(smooth.written.size(), 60u);
	double plainWorst = 0, smoothWorst = 0;
	for (std::size_t k = 8; k < 52; k++)  // frames with 8 neighbours on each side
	{
		plainWorst = std::max(plainWorst, plain.positionError(k));
		smoothWorst = std::max(smoothWorst, smooth.positionError(k));
		// The orientation is the frame's own solve's, to the bit.
		EXPECT_EQ(smooth.written[k].qx, plain.written[k].qx) << k;
		EXPECT_EQ(smooth.written[k].qw, plain.written[k].qw) << k;
	}
	EXPECT_GT(plainWorst, 0.0025);
	// A parabola fits the camera's motion exactly: what is left is the noise, mostly averaged out
	// (a straight line through the same 17 frames would be 8 mm off: the camera accelerates at 0.6 m/s^2).
	EXPECT_LT(smoothWorst, 0.0006);
	// The first and last frames have no neighbour on one side: left as solved.
	EXPECT_NEAR(smooth.positionError(0), plain.positionError(0), 1e-12);
	EXPECT_NEAR(smooth.positionError(59), plain.positionError(59), 1e-12);
}

TEST(FrameRecords, TheSmoothingNeverReachesAcrossALoopCorrection)
{
	// Frames 30 on were tracked in a corrected map: frame 29's fit has no frame after it (it is
	// left as solved), frame 31's only one before it (also left).
	const TNoisyRun plain(0), split(8, 60, 30), whole(8);
	EXPECT_NEAR(split.positionError(29), plain.positionError(29), 1e-12);
	EXPECT_NEAR(split.positionError(30), plain.positionError(30), 1e-12);
	EXPECT_NEAR(split.positionError(31), plain.positionError(31), 1e-12);
	EXPECT_GT(std::abs(whole.positionError(29) - plain.positionError(29)), 1e-4);
	// Farther from the correction the fits have their frames again.
	EXPECT_LT(split.positionError(40), 0.0006);
}

TEST(FrameRecords, TheSmoothingNeverReachesAcrossALoss)
{
	// Frames 25-34 were lost (coasted on a guess): the frames just before and after have no two
	// tracked neighbours on that side and stay as solved, and so do the coasted ones, which keep
	// their step from frame 24; farther from the gap the fits are whole again.
	const TNoisyRun plain(0, 60, -1, 25, 35), gap(8, 60, -1, 25, 35);
	for (const std::size_t k : {23u, 24u, 35u, 36u})
		EXPECT_NEAR(gap.positionError(k), plain.positionError(k), 1e-12) << k;
	EXPECT_LT(gap.positionError(15), 0.0006);
	EXPECT_LT(gap.positionError(45), 0.0006);
	for (std::size_t k = 25; k < 35; k++) EXPECT_EQ(gap.written[k].tx, plain.written[k].tx) << k;
	// Without the loss the same frames are smoothed across where it was.
	const TNoisyRun whole(8);
	EXPECT_GT(std::abs(whole.positionError(24) - plain.positionError(24)), 1e-4);
}

TEST(FrameRecords, TheSmoothingNeverReachesAcrossARelocalisation)
{
	// Frame 30 was relocalised: the frames before it had drifted 3 cm, the jump onto it is that
	// drift, not a motion. The fits either side end there, as at a loop correction: frames 29 and
	// 30 have no two neighbours on that side and stay as solved (a fit through the jump pulled
	// them 1 cm towards each other before). The corrections' averaging ends at the same stretches.
	const TNoisyRun plain(0, 60, -1, -1, -1, 30), reloc(8, 60, -1, -1, -1, 30);
	for (const std::size_t k : {28u, 29u, 30u, 31u})
		EXPECT_NEAR(reloc.positionError(k), plain.positionError(k), 1e-12) << k;
	EXPECT_NEAR(reloc.positionError(15), 0.03, 0.0006);  // the drift, smoothed
	EXPECT_LT(reloc.positionError(45), 0.0006);
}

TEST(FrameRecords, ARunWithoutStampsIsNotSmoothed)
{
	// A rawlog without stamps gives every frame the same one: no time to fit a motion in.
	CFrameRecords records(false, 0, 8);
	for (int k = 0; k < 30; k++)
	{
		CFrameRecords::TRecord r = record(k, mrpt::poses::CPose3D(0.003 * k + (k % 2 ? 0.001 : -0.001), 0, 0, 0, 0, 0));
		r.t = 5.0;
		r.anchor = TAnchor{TKeyFrameId(0), r.online};
		records.add(r, TFrameLogRow());
	}
	const TTrajectory t = records.smoothed(
		[] {
			return std::map<TKeyFrameId, mrpt::poses::CPose3D>{{0, mrpt::poses::CPose3D()}};
		});
	ASSERT_EQ(t.size(), 30u);
	for (int k = 0; k < 30; k++)
		EXPECT_NEAR(t[static_cast<std::size_t>(k)].tx, 0.003 * k + (k % 2 ? 0.001 : -0.001), 1e-15) << k;
}

TEST(FrameRecords, TheKeyFrameCarriedTrajectoryUsesNoLaterFrame)
{
	// trajectory.txt (issue 62): each frame's pose is the one tracking measured relative to its
	// keyframe, carried by that keyframe's final pose, whatever the smoothing options: adding
	// later frames changes no earlier pose, lost frames keep their coasted pose. smoothed() (the
	// same records) moves them.
	const std::map<TKeyFrameId, mrpt::poses::CPose3D> finals{{0, mrpt::poses::CPose3D(0, 0.01, 0, 0.002, 0, 0)}};
	CFrameRecords records(true, 3, 8);
	std::vector<TTrajectory> soFar;
	for (int k = 0; k < 40; k++)
	{
		const mrpt::poses::CPose3D measured(0.003 * k + (k % 2 ? 0.0015 : -0.0015), 0, 0, 0, 0, 0);
		CFrameRecords::TRecord r = record(k, measured, k < 20 || k >= 25);
		r.anchor = TAnchor{TKeyFrameId(0), measured};
		records.add(r, TFrameLogRow());
		soFar.push_back(records.trajectory([&] { return finals; }));
	}
	const TTrajectory all = soFar.back(), smooth = records.smoothed([&] { return finals; });
	ASSERT_EQ(all.size(), 40u);
	double moved = 0;
	for (std::size_t k = 0; k < 40; k++)
	{
		const mrpt::poses::CPose3D want =
			finals.at(0) +
			mrpt::poses::CPose3D(0.003 * static_cast<double>(k) + (k % 2 ? 0.0015 : -0.0015), 0, 0, 0, 0, 0);
		EXPECT_LT((all[k].asPose().asVectorVal() - want.asVectorVal()).norm(), 1e-12) << k;
		EXPECT_EQ(soFar[k][k].tx, all[k].tx) << "frame " << k << " changed once later frames came";
		moved += std::abs(smooth[k].tx - all[k].tx);
	}
	EXPECT_GT(moved, 0.01) << "the smoothed trajectory evens out the zig-zag and fills in the lost frames";
}

TEST(FrameRecords, TheSmoothedTrajectoryUsesTheMeasuredPosesNotTheFilteredOnes)
{
	// The online pose a robot got is filtered ([OnlinePose]); mapping's corrections are measured
	// against the pose tracking solved, so the filter never reaches trajectory_smoothed.txt.
	TScene plain(3), filtered(3);
	CFrameRecords shifted(false, 3);
	// The same records with their online poses moved 1 cm (what a filter's lag could do).
	for (int k = 0; k < 40; k++)
	{
		CFrameRecords::TRecord r = record(k, filtered.truth[static_cast<std::size_t>(k)]);
		const int s = k / 10, ab = k % 2;
		r.anchor = TAnchor{static_cast<TKeyFrameId>(2 * s + ab),
						   r.online - filtered.truth[static_cast<std::size_t>(10 * s + 5 * ab)]};
		r.generation = k < 20 ? 1 : 2;
		r.online = mrpt::poses::CPose3D(0.01, 0, 0, 0, 0, 0) + r.online;
		shifted.add(r, TFrameLogRow());
	}
	const TTrajectory a = plain.trajectory(), b = shifted.smoothed([&] { return filtered.finalKeyFrames; });
	ASSERT_EQ(a.size(), b.size());
	for (std::size_t k = 0; k < a.size(); k++)
		EXPECT_NEAR((a[k].asPose().asVectorVal() - b[k].asPose().asVectorVal()).norm(), 0.0, 1e-12) << k;
}
