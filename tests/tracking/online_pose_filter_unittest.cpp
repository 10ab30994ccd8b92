// COnlinePoseFilter: the online pose (what a robot gets) filtered causally: less frame-to-frame
// noise than the single-frame solves, no lag on a steadily moving camera, and a restart where the
// map or the camera jumped.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

#include "mrpt_yesslam/tracking/COnlinePoseFilter.h"

using namespace mrpt_yesslam;

namespace
{
// A hand-held camera at 30 Hz: walking at 0.3 m/s along x, swaying 5 cm in y with a 2 s period.
Eigen::Vector3d truePosition(double t)
{
	return {0.3 * t, 0.05 * std::sin(M_PI * t), 0.01 * t};
}

struct TRun
{
	std::vector<Eigen::Vector3d> truth, solved, filtered;
};

// Each solve off by 3 mm (per axis, Gaussian), as a real single-frame pose solve.
TRun run(const COnlinePoseFilter::TOptions& o, int frames = 300, unsigned seed = 7)
{
	COnlinePoseFilter filter(o);
	std::mt19937 rng(seed);
	std::normal_distribution<double> noise(0.0, 0.003);
	TRun r;
	for (int k = 0; k < frames; k++)
	{
		const double t = k / 30.0;
		const Eigen::Vector3d p = truePosition(t), z = p + Eigen::Vector3d(noise(rng), noise(rng), noise(rng));
		const auto out = filter.update(t, mrpt::poses::CPose3D(z.x(), z.y(), z.z(), 0.1, 0.2, 0.3), true, false);
		r.truth.push_back(p);
		r.solved.push_back(z);
		r.filtered.push_back({out.x(), out.y(), out.z()});
	}
	return r;
}

double rmsError(const std::vector<Eigen::Vector3d>& est, const std::vector<Eigen::Vector3d>& truth, std::size_t from)
{
	double s = 0;
	for (std::size_t k = from; k < est.size(); k++) s += (est[k] - truth[k]).squaredNorm();
	return std::sqrt(s / static_cast<double>(est.size() - from));
}

// Median over frames of |estimated step - true step|: the trajectory's jitter.
double jitter(const std::vector<Eigen::Vector3d>& est, const std::vector<Eigen::Vector3d>& truth, std::size_t from)
{
	std::vector<double> d;
	for (std::size_t k = from + 1; k < est.size(); k++)
		d.push_back(((est[k] - est[k - 1]) - (truth[k] - truth[k - 1])).norm());
	std::nth_element(d.begin(), d.begin() + static_cast<std::ptrdiff_t>(d.size() / 2), d.end());
	return d[d.size() / 2];
}
}  // namespace

TEST(OnlinePoseFilter, ThePositionIsCloserAndStepsAsTheCameraWithoutLaterFrames)
{
	const TRun r = run(COnlinePoseFilter::TOptions());
	// After its first half second the filter has a velocity.
	EXPECT_LT(rmsError(r.filtered, r.truth, 15), 0.8 * rmsError(r.solved, r.truth, 15));
	EXPECT_LT(jitter(r.filtered, r.truth, 15), 0.6 * jitter(r.solved, r.truth, 15));
	// Causal: a frame's output does not change when later frames come (the same run cut short).
	const TRun cut = run(COnlinePoseFilter::TOptions(), 100);
	for (std::size_t k = 0; k < 100; k++) EXPECT_EQ(cut.filtered[k], r.filtered[k]) << k;
	// Off: the solved positions as they are.
	COnlinePoseFilter::TOptions off;
	off.positionSigma = 0;
	const TRun raw = run(off);
	for (std::size_t k = 0; k < raw.solved.size(); k++) EXPECT_EQ(raw.filtered[k], raw.solved[k]) << k;
}

TEST(OnlinePoseFilter, TheOrientationIsTheSolvesAndJumpsRestartTheFilter)
{
	COnlinePoseFilter f;
	mrpt::poses::CPose3D out;
	for (int k = 0; k < 30; k++)
		out = f.update(k / 30.0, mrpt::poses::CPose3D(0.01 * k, 0, 0, 0.01 * k, 0, 0), true, false);
	EXPECT_NEAR(out.yaw(), 0.29, 1e-12);
	// A camera jerked 8 cm sideways within a frame: far beyond the gate, the measurement is taken.
	const mrpt::poses::CPose3D jerked(0.30, 0.08, 0, 0.3, 0, 0);
	out = f.update(1.0, jerked, true, false);
	EXPECT_NEAR(out.y(), 0.08, 1e-12);
	EXPECT_TRUE(f.jumped()) << "a jerk beyond the gate is said";
	// The map jumped under the pose (a loop correction): the measurement as it is, then filtered again.
	const mrpt::poses::CPose3D corrected(0.5, 0.5, 0, 0.3, 0, 0);
	out = f.update(1.0 + 1 / 30.0, corrected, true, true);
	EXPECT_EQ(out.x(), 0.5);
	EXPECT_FALSE(f.jumped()) << "a map correction is no jerk of the camera";
	// A lost frame reports its coasted pose, and the next tracked one starts again.
	const mrpt::poses::CPose3D coasted(0.6, 0.5, 0, 0.3, 0, 0);
	EXPECT_EQ(f.update(1.1, coasted, false, false).x(), 0.6);
	EXPECT_EQ(f.update(1.1 + 1 / 30.0, mrpt::poses::CPose3D(0.61, 0.5, 0, 0.3, 0, 0), true, false).x(), 0.61);
}
