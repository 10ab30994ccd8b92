#include "mrpt_yesslam/io/WorldFrame.h"
#include "mrpt_yesslam/util/TextParsing.h"

#include <mrpt/math/CMatrixFixed.h>
#include <mrpt/math/CQuaternion.h>

#include <Eigen/Dense>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <random>
#include <sstream>

#include "mrpt_yesslam/util/Error.h"

namespace mrpt_yesslam
{
namespace
{
constexpr double kMaxTiltDeg = 45;                  // a floor's normal from the first camera's up
constexpr double kMinBelow = 0.2, kMaxBelow = 4.0;  // m: where a floor can lie under the first camera
constexpr double kPlaneTol = 0.02;                  // m: a point on a plane (depth noise at 2-3 m)
constexpr std::size_t kMaxPoints = 40000;           // enough for a plane, cheap at the end of a run

// The unit normal of the least-squares plane through `pts`, turned towards `up`.
Eigen::Vector3d planeNormal(const std::vector<Eigen::Vector3d>& pts, const Eigen::Vector3d& up)
{
	Eigen::Vector3d mean = Eigen::Vector3d::Zero();
	for (const auto& p : pts) mean += p;
	mean /= static_cast<double>(pts.size());
	Eigen::Matrix3d C = Eigen::Matrix3d::Zero();
	for (const auto& p : pts) C += (p - mean) * (p - mean).transpose();
	const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> es(C);
	Eigen::Vector3d n = es.eigenvectors().col(0);  // smallest eigenvalue first
	return n.dot(up) < 0 ? Eigen::Vector3d(-n) : n;
}
}  // namespace

const char* worldFrameName(TWorldFrame::EKind kind)
{
	return kind == TWorldFrame::EKind::ZUp ? "zup" : "optical";
}

std::string TWorldFrame::describe() const
{
	std::string s;
	if (kind == EKind::Optical)
		s = "world frame: optical (the first keyframe's camera: x right, y down, z forward; [System] worldFrame = "
			"optical)";
	else if (floorSeen)
	{
		char buf[160];
		std::snprintf(buf, sizeof(buf), "; the first camera %.3f m above it", cameraHeight);
		s = std::string(
				"world frame: zup (x forward, y left, z up), levelled by the floor plane: floor at z = 0, origin under "
				"the first camera") +
			buf;
	}
	else
		s = "world frame: zup (x forward, y left, z up), levelled by the first camera's axes (no floor seen): origin "
			"at the first camera";
	mrpt::math::CQuaternionDouble q;
	worldFromMap.getAsQuaternion(q);
	char buf[200];
	std::snprintf(buf, sizeof(buf), "\nT_world_map: %.9f %.9f %.9f %.9f %.9f %.9f %.9f",
				  withoutNegativeZero(worldFromMap.x()), withoutNegativeZero(worldFromMap.y()),
				  withoutNegativeZero(worldFromMap.z()), withoutNegativeZero(q.x()), withoutNegativeZero(q.y()),
				  withoutNegativeZero(q.z()), withoutNegativeZero(q.r()));
	return s + buf + " (map = the first keyframe's camera, optical axes)";
}

TWorldFrame estimateZUpWorldFrame(const std::vector<mrpt::math::TPoint3D>& points,
								  const mrpt::poses::CPose3D& firstCamera)
{
	const Eigen::Matrix3d R0 = firstCamera.getRotationMatrix().asEigen();
	const Eigen::Vector3d c(firstCamera.x(), firstCamera.y(), firstCamera.z());
	const Eigen::Vector3d camUp = -R0.col(1), camForward = R0.col(2);

	std::vector<Eigen::Vector3d> pts;
	const std::size_t step = std::max<std::size_t>(1, points.size() / kMaxPoints);
	for (std::size_t i = 0; i < points.size(); i += step)
	{
		const auto& p = points[i];
		if (std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.z)) pts.emplace_back(p.x, p.y, p.z);
	}

	TWorldFrame f;
	f.kind = TWorldFrame::EKind::ZUp;
	Eigen::Vector3d up = camUp, origin = c;
	// The horizontal plane with the most points (deterministic RANSAC): its normal is "up".
	const std::size_t minSupport = std::max<std::size_t>(100, pts.size() / 30);
	std::size_t bestCount = 0;
	Eigen::Vector3d bestN = camUp;
	double bestH = 0;
	if (pts.size() >= minSupport)
	{
		std::mt19937 rng(12345);
		std::uniform_int_distribution<std::size_t> pick(0, pts.size() - 1);
		const double cosTilt = std::cos(kMaxTiltDeg * M_PI / 180);
		for (int it = 0; it < 500; it++)
		{
			const auto &a = pts[pick(rng)], &b = pts[pick(rng)], &d = pts[pick(rng)];
			Eigen::Vector3d n = (b - a).cross(d - a);
			if (n.norm() < 1e-6) continue;
			n.normalize();
			if (n.dot(camUp) < 0) n = -n;
			if (n.dot(camUp) < cosTilt) continue;
			const double h = n.dot(a), below = n.dot(c) - h;
			if (below < kMinBelow || below > kMaxBelow) continue;
			std::size_t count = 0;
			for (const auto& p : pts) count += std::abs(n.dot(p) - h) < kPlaneTol;
			if (count > bestCount) bestCount = count, bestN = n, bestH = h;
		}
	}
	if (bestCount >= minSupport)
	{
		std::vector<Eigen::Vector3d> in;
		for (const auto& p : pts)
			if (std::abs(bestN.dot(p) - bestH) < kPlaneTol) in.push_back(p);
		Eigen::Vector3d n = planeNormal(in, camUp);
		// Along that normal, the lowest layer holding a good share of the best plane's points is
		// the floor (a desk top is as horizontal and often holds more of the points seen).
		const double top = n.dot(c) - kMinBelow, bottom = n.dot(c) - kMaxBelow;
		const double bin = kPlaneTol;
		const int bins = static_cast<int>((top - bottom) / bin) + 1;
		std::vector<std::size_t> hist(static_cast<std::size_t>(bins), 0);
		for (const auto& p : pts)
		{
			const double h = n.dot(p);
			if (h >= bottom && h < top) hist[static_cast<std::size_t>((h - bottom) / bin)]++;
		}
		const std::size_t need = std::max(minSupport, bestCount / 4);
		for (int i = 0; i < bins; i++)
		{
			const std::size_t s = hist[i] + (i > 0 ? hist[i - 1] : 0) + (i + 1 < bins ? hist[i + 1] : 0);
			if (s < need) continue;
			// Refine on the floor's own points: its normal, then its height.
			const double h0 = bottom + (i + 0.5) * bin;
			std::vector<Eigen::Vector3d> floor;
			for (const auto& p : pts)
				if (std::abs(n.dot(p) - h0) < 1.5 * bin) floor.push_back(p);
			const Eigen::Vector3d nf = planeNormal(floor, camUp);
			if (nf.dot(n) > std::cos(10 * M_PI / 180)) n = nf;
			double h = 0;
			for (const auto& p : floor) h += n.dot(p);
			h /= static_cast<double>(floor.size());
			up = n;
			f.floorSeen = true;
			f.cameraHeight = n.dot(c) - h;
			origin = c - f.cameraHeight * n;
			break;
		}
	}
	// x: the first camera's viewing direction on the floor (its up when it looks straight down).
	Eigen::Vector3d x = camForward - camForward.dot(up) * up;
	if (x.norm() < 0.1) x = camUp - camUp.dot(up) * up;
	x.normalize();
	const Eigen::Vector3d y = up.cross(x);
	mrpt::math::CMatrixDouble33 R;
	for (int k = 0; k < 3; k++)
	{
		R(0, k) = x[k];
		R(1, k) = y[k];
		R(2, k) = up[k];
	}
	const Eigen::Vector3d t = -(R.asEigen() * origin);
	mrpt::math::CVectorFixedDouble<3> tv;
	for (int k = 0; k < 3; k++) tv[k] = t[k];
	f.worldFromMap = mrpt::poses::CPose3D(R, tv);
	return f;
}

TTrajectory toWorldFrame(const TTrajectory& traj, const mrpt::poses::CPose3D& worldFromMap)
{
	TTrajectory out;
	out.reserve(traj.size());
	for (const auto& p : traj) out.push_back(TStampedPose::fromPose(p.t, worldFromMap + p.asPose()));
	return out;
}

std::optional<mrpt::poses::CPose3D> readWorldFromMap(const std::string& path)
{
	std::ifstream f(path);
	if (!f) throw InputError(path, "cannot open the trajectory file");
	std::string line;
	while (std::getline(f, line))
	{
		if (line.empty() || line[0] != '#') break;  // the header comes first
		const auto k = line.find("T_world_map:");
		if (k == std::string::npos) continue;
		std::istringstream in(line.substr(k + 12));
		double v[7];
		for (double& x : v)
			if (!(in >> x) || !std::isfinite(x)) throw InputError(path, "unreadable T_world_map line in the header");
		TStampedPose p;
		p.tx = v[0], p.ty = v[1], p.tz = v[2], p.qx = v[3], p.qy = v[4], p.qz = v[5], p.qw = v[6];
		return p.asPose();
	}
	return std::nullopt;
}
}  // namespace mrpt_yesslam
