#include "mrpt_yesslam/eval/GroundTruthFormat.h"

#include <Eigen/Dense>
#include <filesystem>

#include "mrpt_yesslam/io/RgbdCamera.h"
#include "mrpt_yesslam/util/ConfigFile.h"
#include "mrpt_yesslam/util/Error.h"

namespace mrpt_yesslam
{
EGroundTruthFormat parseGroundTruthFormat(const std::string& name, const std::string& option)
{
	const std::string n = lowerAscii(name);
	if (n == "tum") return EGroundTruthFormat::Tum;
	if (n == "bonn") return EGroundTruthFormat::Bonn;
	if (n == "auto") return EGroundTruthFormat::Auto;
	throw InputError(
		"", option + " must be 'tum' (camera poses), 'bonn' (Bonn RGB-D Dynamic marker poses) or 'auto', got '" + name +
				"'");
}

EGroundTruthFormat resolveGroundTruthFormat(const std::string& path, EGroundTruthFormat format)
{
	if (format != EGroundTruthFormat::Auto) return format;
	return isBonnDatasetPath(path) ? EGroundTruthFormat::Bonn : EGroundTruthFormat::Tum;
}

std::string describeGroundTruthFormat(EGroundTruthFormat format)
{
	return format == EGroundTruthFormat::Bonn
			   ? "Bonn RGB-D Dynamic marker poses, converted to the camera's (--gt-format tum takes them as they are)"
			   : "camera poses (TUM)";
}

namespace
{
mrpt::poses::CPose3D poseOf(const Eigen::Matrix3d& R, const Eigen::Vector3d& t)
{
	mrpt::math::CMatrixDouble33 m;
	for (int i = 0; i < 3; i++)
		for (int j = 0; j < 3; j++) m(i, j) = R(i, j);
	return mrpt::poses::CPose3D(m, mrpt::math::CVectorFixedDouble<3>({t.x(), t.y(), t.z()}));
}

// The Bonn dataset's marker-to-camera transform (its README and SOURCE.md in ../shared).
mrpt::poses::CPose3D bonnMarkerToCamera()
{
	Eigen::Matrix3d M;
	M << 1.0157, 0.1828, -0.2389, 0.0009, -0.8431, -0.6413, -0.3009, 0.6147, -0.8085;
	// Its rotation block is a rotation times 1.0593 (rows and columns of that norm, orthogonal to
	// the four printed digits): a similarity, which carries camera-frame points into the markers'
	// metric scaled up by 5.9 % - the Xtion's depth reads that much short (our estimate's Sim(3)
	// scale on the dev slice is 1.05-1.07 too). A pose has no scale: the rotation (the polar
	// decomposition by SVD) keeps the orientation, and the trajectory stays the markers' metric.
	const Eigen::JacobiSVD<Eigen::Matrix3d> svd(M, Eigen::ComputeFullU | Eigen::ComputeFullV);
	Eigen::Matrix3d U = svd.matrixU();
	if ((U * svd.matrixV().transpose()).determinant() < 0) U.col(2) *= -1;
	return poseOf(U * svd.matrixV().transpose(), Eigen::Vector3d(0.0113, -0.0098, 0.0111));
}
}  // namespace

TTrajectory bonnMarkersToCamera(const TTrajectory& markers)
{
	Eigen::Matrix3d R;
	R << -1, 0, 0, 0, 0, 1, 0, 1, 0;  // its own inverse (a half turn)
	const mrpt::poses::CPose3D Tros = poseOf(R, Eigen::Vector3d::Zero()), Tm = bonnMarkerToCamera();
	TTrajectory out;
	out.reserve(markers.size());
	for (const auto& p : markers) out.push_back(TStampedPose::fromPose(p.t, Tros + p.asPose() + Tros + Tm));
	return out;
}

TTrajectory readGroundTruth(const std::string& path, EGroundTruthFormat format)
{
	TTrajectory t = readTumTrajectory(path);
	return resolveGroundTruthFormat(path, format) == EGroundTruthFormat::Bonn ? bonnMarkersToCamera(t) : t;
}
}  // namespace mrpt_yesslam
