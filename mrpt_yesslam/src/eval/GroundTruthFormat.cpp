#include "mrpt_yesslam/eval/GroundTruthFormat.h"

#include <Eigen/Geometry>
#include <Eigen/SVD>
#include <algorithm>
#include <cctype>

#include "mrpt_yesslam/util/Error.h"

namespace mrpt_yesslam
{
EGroundTruthFormat parseGroundTruthFormat(const std::string& name, const std::string& option)
{
	std::string n = name;
	std::transform(n.begin(), n.end(), n.begin(), [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
	if (n == "tum") return EGroundTruthFormat::Tum;
	if (n == "bonn") return EGroundTruthFormat::Bonn;
	throw InputError("", option + " must be 'tum' (camera poses) or 'bonn' (Bonn RGB-D Dynamic marker poses), got '" + name + "'");
}

std::string groundTruthFormatName(EGroundTruthFormat f) { return f == EGroundTruthFormat::Bonn ? "bonn" : "tum"; }

namespace
{
Eigen::Isometry3d isometryOf(const TStampedPose& p)
{
	Eigen::Quaterniond q(p.qw, p.qx, p.qy, p.qz);
	q.normalize();
	Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
	T.linear() = q.toRotationMatrix();
	T.translation() = Eigen::Vector3d(p.tx, p.ty, p.tz);
	return T;
}

TStampedPose stampedOf(double t, const Eigen::Isometry3d& T)
{
	TStampedPose p;
	p.t = t;
	p.tx = T.translation().x();
	p.ty = T.translation().y();
	p.tz = T.translation().z();
	const Eigen::Quaterniond q(T.linear());
	p.qx = q.x();
	p.qy = q.y();
	p.qz = q.z();
	p.qw = q.w();
	return p;
}

// The Bonn dataset's marker-to-camera transform (its README and SOURCE.md in ../shared).
Eigen::Isometry3d bonnMarkerToCamera()
{
	Eigen::Matrix3d M;
	M << 1.0157, 0.1828, -0.2389, 0.0009, -0.8431, -0.6413, -0.3009, 0.6147, -0.8085;
	// Published with a scale and shear error in its rotation block (rows of norm 1.07): the nearest
	// rotation (polar decomposition by SVD) keeps what it means and gives a rigid pose.
	const Eigen::JacobiSVD<Eigen::Matrix3d> svd(M, Eigen::ComputeFullU | Eigen::ComputeFullV);
	Eigen::Matrix3d R = svd.matrixU() * svd.matrixV().transpose();
	if (R.determinant() < 0)
	{
		Eigen::Matrix3d U = svd.matrixU();
		U.col(2) *= -1;
		R = U * svd.matrixV().transpose();
	}
	Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
	T.linear() = R;
	T.translation() = Eigen::Vector3d(0.0113, -0.0098, 0.0111);
	return T;
}
}  // namespace

TTrajectory bonnMarkersToCamera(const TTrajectory& markers)
{
	Eigen::Isometry3d Tros = Eigen::Isometry3d::Identity();
	Tros.linear() << -1, 0, 0, 0, 0, 1, 0, 1, 0;  // its own inverse (a half turn)
	const Eigen::Isometry3d Tm = bonnMarkerToCamera();
	TTrajectory out;
	out.reserve(markers.size());
	for (const auto& p : markers) out.push_back(stampedOf(p.t, Tros * isometryOf(p) * Tros * Tm));
	return out;
}

TTrajectory readGroundTruth(const std::string& path, EGroundTruthFormat format)
{
	TTrajectory t = readTumTrajectory(path);
	return format == EGroundTruthFormat::Bonn ? bonnMarkersToCamera(t) : t;
}
}  // namespace mrpt_yesslam
