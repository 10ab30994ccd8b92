#include "mrpt_yesslam/io/Trajectory.h"

#include <mrpt/math/CQuaternion.h>
#include <mrpt/poses/Lie/SO.h>

#include <Eigen/Dense>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>

#include "mrpt_yesslam/util/TextParsing.h"
#include "mrpt_yesslam/util/AtomicFile.h"
#include "mrpt_yesslam/util/Error.h"

namespace mrpt_yesslam
{
mrpt::poses::CPose3D TStampedPose::asPose() const
{
	const double n = std::sqrt(qx * qx + qy * qy + qz * qz + qw * qw);
	const mrpt::math::CQuaternionDouble q(qw / n, qx / n, qy / n, qz / n);
	return mrpt::poses::CPose3D(q, tx, ty, tz);
}

TTrajectory uniqueSortedByTime(const TTrajectory& traj)
{
	std::map<double, TStampedPose> m;
	for (const auto& p : traj) m[p.t] = p;  // later lines win, like a Python dict
	TTrajectory out;
	out.reserve(m.size());
	for (const auto& kv : m) out.push_back(kv.second);
	return out;
}

mrpt::poses::CPose3D interpolatePose(const mrpt::poses::CPose3D& a, const mrpt::poses::CPose3D& b, double s)
{
	const mrpt::math::CMatrixDouble33 Ra = a.getRotationMatrix();
	const mrpt::math::CMatrixDouble33 dR(Ra.asEigen().transpose() * b.getRotationMatrix().asEigen());
	const auto w = mrpt::poses::Lie::SO<3>::log(dR);
	mrpt::poses::CPose3D p;
	p.setRotationMatrix(mrpt::math::CMatrixDouble33(
		Ra.asEigen() *
		mrpt::poses::Lie::SO<3>::exp(mrpt::poses::Lie::SO<3>::tangent_vector(w.asEigen() * s)).asEigen()));
	p.x((1 - s) * a.x() + s * b.x());
	p.y((1 - s) * a.y() + s * b.y());
	p.z((1 - s) * a.z() + s * b.z());
	return p;
}

void interpolateUntracked(TTrajectory& traj, const std::vector<bool>& tracked)
{
	const std::size_t n = std::min(traj.size(), tracked.size());
	for (std::size_t i = 0; i < n;)
	{
		if (tracked[i])
		{
			i++;
			continue;
		}
		std::size_t j = i;
		while (j < n && !tracked[j]) j++;
		// Untracked run [i, j): between tracked i - 1 and j when both exist.
		if (i > 0 && j < n && traj[j].t > traj[i - 1].t)
		{
			const TStampedPose a = traj[i - 1], b = traj[j];
			const mrpt::poses::CPose3D pa = a.asPose(), pb = b.asPose();
			for (std::size_t k = i; k < j; k++)
				traj[k] = TStampedPose::fromPose(
					traj[k].t, interpolatePose(pa, pb, std::clamp((traj[k].t - a.t) / (b.t - a.t), 0.0, 1.0)));
		}
		i = j;
	}
}

TStampedPose TStampedPose::fromPose(double t, const mrpt::poses::CPose3D& p)
{
	mrpt::math::CQuaternionDouble q;
	p.getAsQuaternion(q);
	TStampedPose s;
	s.t = t;
	s.tx = p.x();
	s.ty = p.y();
	s.tz = p.z();
	s.qx = q.x();
	s.qy = q.y();
	s.qz = q.z();
	s.qw = q.r();
	return s;
}

TTrajectory parseTumTrajectory(const std::string& text, const std::string& name)
{
	TTrajectory traj;
	const auto lines = splitLines(text);
	for (std::size_t i = 0; i < lines.size(); i++)
	{
		if (isCommentOrBlank(lines[i])) continue;
		const std::string where = "line " + std::to_string(i + 1) + ": ";
		const auto f = splitFields(lines[i]);
		if (f.size() != 8)
			throw InputError(name, where + "expected 8 numbers (timestamp tx ty tz qx qy qz qw), found " +
									   std::to_string(f.size()) + " fields");
		double v[8];
		for (int k = 0; k < 8; k++)
			if (!parseFiniteDouble(f[k], v[k]))
				throw InputError(name,
								 where + "field " + std::to_string(k + 1) + " '" + f[k] + "' is not a finite number");
		TStampedPose p;
		p.t = v[0];
		p.tx = v[1];
		p.ty = v[2];
		p.tz = v[3];
		p.qx = v[4];
		p.qy = v[5];
		p.qz = v[6];
		p.qw = v[7];
		const double qn = std::sqrt(p.qx * p.qx + p.qy * p.qy + p.qz * p.qz + p.qw * p.qw);
		if (qn < 1e-6) throw InputError(name, where + "quaternion has zero norm");
		traj.push_back(p);
	}
	return traj;
}

TTrajectory readTumTrajectory(const std::string& path)
{
	return parseTumTrajectory(readTextFile(path), path);
}

std::string formatTumTrajectory(const TTrajectory& traj, const std::string& header)
{
	std::string out;
	if (!header.empty())
	{
		for (const auto& l : splitLines(header)) out += "# " + l + "\n";
	}
	char buf[256];
	const auto z = withoutNegativeZero;  // issue 43: no "-0.000000000"
	for (const auto& p : traj)
	{
		std::snprintf(buf, sizeof(buf), "%.6f %.9f %.9f %.9f %.9f %.9f %.9f %.9f\n", p.t, z(p.tx), z(p.ty), z(p.tz),
					  z(p.qx), z(p.qy), z(p.qz), z(p.qw));
		out += buf;
	}
	return out;
}

void writeTumTrajectory(const std::string& path, const TTrajectory& traj, const std::string& header)
{
	writeFileAtomically(path, formatTumTrajectory(traj, header));
}
}  // namespace mrpt_yesslam
