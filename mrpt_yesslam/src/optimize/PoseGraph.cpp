#include "mrpt_yesslam/optimize/PoseGraph.h"

#include <ceres/ceres.h>
#include <ceres/rotation.h>

#include <array>

#include "mrpt_yesslam/geometry/CPoseOptimizer.h"

namespace mrpt_yesslam
{
namespace
{
// Parameters of each vertex as in bundle adjustment: world-to-camera angle-axis r and translation
// t (X_c = R X_w + t). For an edge, T_ab = T_wa^-1 T_wb = T_aw T_bw^-1: R_ab = R_a R_b^T,
// t_ab = t_a - R_ab t_b. Residual: the rotation error angle-axis(R_meas^T R_ab) and the
// translation error t_ab - t_meas, in camera a's frame (Ceres' pose_graph_3d example).
struct TRelativePoseCost
{
	TRelativePoseCost(const mrpt::poses::CPose3D& m, double w) : weight(w)
	{
		// T_ab of the measurement expressed the same way: camera b in camera a's frame.
		const auto R = m.getRotationMatrix();
		double Rm[9];
		for (int r = 0; r < 3; r++)
			for (int c = 0; c < 3; c++) Rm[c * 3 + r] = R(r, c);  // column-major for ceres
		ceres::RotationMatrixToQuaternion(Rm, qm);
		tm[0] = m.x(), tm[1] = m.y(), tm[2] = m.z();
	}

	template <typename T>
	bool operator()(const T* ra, const T* ta, const T* rb, const T* tb, T* res) const
	{
		T qa[4], qb[4], qbInv[4], qab[4];
		ceres::AngleAxisToQuaternion(ra, qa);
		ceres::AngleAxisToQuaternion(rb, qb);
		qbInv[0] = qb[0], qbInv[1] = -qb[1], qbInv[2] = -qb[2], qbInv[3] = -qb[3];
		ceres::QuaternionProduct(qa, qbInv, qab);  // R_a R_b^T
		// T_ab maps points of b's frame into a's frame: with T_xw mapping world to camera x,
		// T_ab = T_aw T_wb = T_aw (T_bw)^-1, so R_ab = R_a R_b^T and t_ab = t_a - R_ab t_b.
		T Rt[3];
		ceres::QuaternionRotatePoint(qab, tb, Rt);
		const T tab[3] = {ta[0] - Rt[0], ta[1] - Rt[1], ta[2] - Rt[2]};
		const T qmInv[4] = {T(qm[0]), T(-qm[1]), T(-qm[2]), T(-qm[3])};
		T qe[4], e[3];
		ceres::QuaternionProduct(qmInv, qab, qe);
		ceres::QuaternionToAngleAxis(qe, e);
		for (int i = 0; i < 3; i++)
		{
			res[i] = T(weight) * e[i];
			res[3 + i] = T(weight) * (tab[i] - T(tm[i]));
		}
		return true;
	}

	double qm[4], tm[3], weight;
};
}  // namespace

std::map<TKeyFrameId, mrpt::poses::CPose3D> optimisePoseGraph(
	const std::map<TKeyFrameId, mrpt::poses::CPose3D>& initial, const std::vector<TPoseGraphEdge>& edges,
	const std::set<TKeyFrameId>& fixed, int iterations, double* finalCost)
{
	std::map<TKeyFrameId, std::array<double, 6>> params;
	for (const auto& [id, p] : initial)
	{
		auto& a = params[id];
		cameraPoseToParams(p, a.data(), a.data() + 3);
	}
	ceres::Problem problem;
	for (const auto& e : edges)
	{
		auto ia = params.find(e.a), ib = params.find(e.b);
		if (ia == params.end() || ib == params.end()) continue;
		// The transform from b's frame to a's frame is the pose of camera b seen from camera a,
		// T_w_a^-1 T_w_b: the edge's relative pose as it is.
		auto* cost = new ceres::AutoDiffCostFunction<TRelativePoseCost, 6, 3, 3, 3, 3>(
			new TRelativePoseCost(e.relative, e.weight));
		problem.AddResidualBlock(cost, nullptr, ia->second.data(), ia->second.data() + 3, ib->second.data(),
								 ib->second.data() + 3);
	}
	for (const auto id : fixed)
		if (auto it = params.find(id); it != params.end() && problem.HasParameterBlock(it->second.data()))
		{
			problem.SetParameterBlockConstant(it->second.data());
			problem.SetParameterBlockConstant(it->second.data() + 3);
		}
	ceres::Solver::Options so;
	so.linear_solver_type = ceres::SPARSE_NORMAL_CHOLESKY;
	so.max_num_iterations = iterations;
	so.num_threads = 1;
	so.logging_type = ceres::SILENT;
	ceres::Solver::Summary sum;
	ceres::Solve(so, &problem, &sum);
	if (finalCost) *finalCost = sum.final_cost;
	std::map<TKeyFrameId, mrpt::poses::CPose3D> out;
	for (const auto& [id, a] : params) out[id] = cameraPoseFromParams(a.data(), a.data() + 3);
	return out;
}
}  // namespace mrpt_yesslam
