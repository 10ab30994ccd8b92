#include "mrpt_yesslam/geometry/Alignment.h"

#include <Eigen/Dense>

namespace mrpt_yesslam
{
TAlignment alignPositions(const std::vector<Eigen::Vector3d>& model, const std::vector<Eigen::Vector3d>& data,
						  bool sim3)
{
	const std::size_t n = model.size();
	Eigen::Vector3d mm = Eigen::Vector3d::Zero(), md = Eigen::Vector3d::Zero();
	for (std::size_t i = 0; i < n; i++)
	{
		mm += model[i];
		md += data[i];
	}
	mm /= static_cast<double>(n);
	md /= static_cast<double>(n);
	Eigen::Matrix3d W = Eigen::Matrix3d::Zero();
	double modelVar = 0;
	for (std::size_t i = 0; i < n; i++)
	{
		const Eigen::Vector3d a = model[i] - mm, b = data[i] - md;
		W += a * b.transpose();
		modelVar += a.squaredNorm();
	}
	// evaluate_ate.py: U,d,Vh = svd(W^T); S = diag(1,1,det(U)det(Vh)<0 ? -1 : 1); rot = U S Vh.
	Eigen::JacobiSVD<Eigen::Matrix3d> svd(W.transpose(), Eigen::ComputeFullU | Eigen::ComputeFullV);
	const Eigen::Matrix3d U = svd.matrixU();
	const Eigen::Matrix3d Vh = svd.matrixV().transpose();
	Eigen::Matrix3d S = Eigen::Matrix3d::Identity();
	if (U.determinant() * Vh.determinant() < 0) S(2, 2) = -1;
	TAlignment a;
	a.R = U * S * Vh;
	a.sim3 = sim3;
	if (sim3 && modelVar > 0) a.scale = (svd.singularValues().asDiagonal() * S).trace() / modelVar;
	a.t = md - a.scale * a.R * mm;
	return a;
}

}  // namespace mrpt_yesslam
