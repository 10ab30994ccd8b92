#include "MapCorrection.h"

#include <Eigen/Geometry>
#include <optional>

namespace mrpt_yesslam::sparse_map
{
namespace
{
// The nearest rotation (through a normalised quaternion). A correction writes T_new, computed from
// T_old by composition: with T_old's rotation off orthonormal by e, T_new (T_old)^-1 T_old is off
// by 3e, so a keyframe never re-estimated (the fixed first one) drifted off by a factor of three per
// correction and its pose became garbage after some thirty loop corrections.
mrpt::poses::CPose3D orthonormalised(const mrpt::poses::CPose3D& p)
{
	Eigen::Quaterniond q(p.getRotationMatrix().asEigen());
	q.normalize();
	mrpt::poses::CPose3D out = p;
	out.setRotationMatrix(mrpt::math::CMatrixDouble33(q.toRotationMatrix()));
	return out;
}
}  // namespace

bool addLoopEdge(TSparseMapStore& s, TKeyFrameId a, TKeyFrameId b)
{
	const auto ia = s.keyFrames.find(a), ib = s.keyFrames.find(b);
	if (ia == s.keyFrames.end() || ib == s.keyFrames.end() || a == b) return false;
	ia->second->loopEdges.insert(b);
	ib->second->loopEdges.insert(a);
	return true;
}

std::vector<std::pair<TKeyFrameId, TKeyFrameId>> essentialGraph(const TSparseMapStore& s, int minWeight)
{
	std::set<std::pair<TKeyFrameId, TKeyFrameId>> edges;
	auto add = [&](TKeyFrameId a, TKeyFrameId b)
	{
		if (a == b) return;
		const auto ia = s.keyFrames.find(a), ib = s.keyFrames.find(b);
		if (ia == s.keyFrames.end() || ib == s.keyFrames.end() || ia->second->bad || ib->second->bad) return;
		edges.insert({std::min(a, b), std::max(a, b)});
	};
	for (const auto& [id, kf] : s.keyFrames)
	{
		if (kf->bad) continue;
		if (kf->parent) add(id, *kf->parent);
		for (const auto& [other, w] : kf->connections)
			if (w >= minWeight) add(id, other);
		for (const auto other : kf->loopEdges) add(id, other);
	}
	return {edges.begin(), edges.end()};
}

void correct(TSparseMapStore& s, const std::map<TKeyFrameId, mrpt::poses::CPose3D>& poses, bool propagate,
			 const std::set<TPointId>& skip)
{
	// Each moved keyframe's correction D = T_new (T_old)^-1, applied to what moves with it.
	std::map<TKeyFrameId, mrpt::poses::CPose3D> delta;
	for (const auto& [id, p] : poses)
		if (auto it = s.keyFrames.find(id); it != s.keyFrames.end() && !it->second->bad)
			delta[id] = p + (-it->second->pose);
	if (propagate)
		for (const auto& [id, kf] : s.keyFrames)
		{
			if (kf->bad || delta.count(id)) continue;
			std::optional<TKeyFrameId> a = kf->parent;
			for (std::size_t hops = 0; a && !delta.count(*a) && hops <= s.keyFrames.size(); hops++)
				a = s.keyFrames.at(*a)->parent;
			if (a && delta.count(*a)) delta[id] = delta.at(*a);
		}
	if (!propagate) s.correctedBy.clear();
	for (auto& [pid, p] : s.points)
	{
		if (p.bad || skip.count(pid)) continue;
		const mrpt::poses::CPose3D* D = nullptr;
		if (propagate)
		{
			// A point the group step moved follows the keyframe that moved it, not its creator:
			// moved once with the group keyframe and again with its creator's correction, it
			// landed where neither puts it.
			const auto cb = s.correctedBy.find(pid);
			const TKeyFrameId anchor = cb != s.correctedBy.end() ? cb->second : p.firstKeyFrame;
			if (s.keyFrames.count(anchor))
				if (auto it = delta.find(s.goodAncestor(anchor)); it != delta.end()) D = &it->second;
		}
		else
			for (const auto& [k, kp] : p.observations)
				if (auto it = delta.find(k); it != delta.end())
				{
					D = &it->second;
					s.correctedBy[pid] = k;
					break;
				}
		if (!D) continue;
		mrpt::math::TPoint3D q;
		D->composePoint(p.position, q);
		p.position = q;
	}
	for (const auto& [id, D] : delta)
	{
		auto& kf = *s.keyFrames.at(id);
		const auto given = poses.find(id);
		kf.pose = orthonormalised(given != poses.end() ? given->second : D + kf.pose);
	}
	if (propagate) s.correctedBy.clear();
	s.generation++;
}

}  // namespace mrpt_yesslam::sparse_map
