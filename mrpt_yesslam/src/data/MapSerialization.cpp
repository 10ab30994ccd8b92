#include "MapSerialization.h"

#include <cmath>
#include <ostream>
#include <stdexcept>

#include "mrpt_yesslam/util/BinaryIO.h"

namespace mrpt_yesslam::sparse_map
{
void serialize(const TSparseMapStore& s, std::ostream& out)
{
	using namespace binio;
	put<std::uint32_t>(out, CSparseMap::kSerialVersion);
	put<std::uint64_t>(out, s.nextKeyFrame);
	put<std::int64_t>(out, s.nextPoint);
	put<std::uint64_t>(out, s.generation);
	put<std::uint64_t>(out, s.keyFrames.size());
	for (const auto& [id, kf] : s.keyFrames) kf->serialize(out);
	// Good points only, by id (the table's order is not deterministic; a saved map should be).
	std::vector<TPointId> ids;
	for (const auto& [id, p] : s.points)
		if (!p.bad) ids.push_back(id);
	std::sort(ids.begin(), ids.end());
	put<std::uint64_t>(out, ids.size());
	for (TPointId id : ids) s.points.at(id).serialize(out);
}

std::unique_ptr<TSparseMapStore> deserialize(std::istream& in)
{
	using namespace binio;
	getVersion(in, "map", CSparseMap::kSerialVersion);
	const auto nextKf = get<std::uint64_t>(in, "map keyframe counter");
	const auto nextPt = get<std::int64_t>(in, "map point counter");
	const auto gen = get<std::uint64_t>(in, "map generation");
	const auto nk = get<std::uint64_t>(in, "map keyframe count");
	if (nk > (1u << 24)) throw std::runtime_error("implausible keyframe count reading map");
	// The counters give the next ids: far beyond any map (or negative), they would overflow.
	if (nextKf > (std::uint64_t(1) << 40) || nextPt < 0 || nextPt > (std::int64_t(1) << 50))
		throw std::runtime_error("id counter out of range reading map");
	std::map<TKeyFrameId, std::shared_ptr<CKeyFrame>> kfs;
	for (std::uint64_t k = 0; k < nk; k++)
	{
		auto kf = std::make_shared<CKeyFrame>(CKeyFrame::deserialize(in));
		if (kf->id >= nextKf || !kfs.emplace(kf->id, kf).second)
			throw std::runtime_error("keyframe id out of place reading map");
	}
	const auto np = get<std::uint64_t>(in, "map point count");
	if (np > (1u << 28)) throw std::runtime_error("implausible point count reading map");
	std::unordered_map<TPointId, CMapPoint> pts;
	pts.reserve(np);
	for (std::uint64_t k = 0; k < np; k++)
	{
		CMapPoint p = CMapPoint::deserialize(in);
		if (p.id < 0 || p.id >= nextPt || p.bad) throw std::runtime_error("map point id out of place reading map");
		const TPointId id = p.id;
		if (!pts.emplace(id, std::move(p)).second) throw std::runtime_error("map point stored twice reading map");
	}
	// Every reference must resolve, both ways, before anything uses the map.
	const auto known = [&](TKeyFrameId id) { return kfs.count(id) != 0; };
	for (const auto& [id, p] : pts)
		for (const auto& [k, kp] : p.observations)
		{
			const auto it = kfs.find(k);
			if (it == kfs.end() || it->second->bad || kp >= it->second->mapPoints.size() ||
				it->second->mapPoints[kp] != id)
				throw std::runtime_error("map point observation does not match its keyframe reading map");
		}
	std::size_t goodKfs = 0;
	for (const auto& [id, kf] : kfs)
	{
		if (!kf->bad) goodKfs++;
		for (std::size_t i = 0; i < kf->mapPoints.size(); i++)
		{
			const TPointId pid = kf->mapPoints[i];
			if (pid < 0) continue;
			const auto it = pts.find(pid);
			if (it == pts.end()) throw std::runtime_error("keyframe names an unknown map point reading map");
			// Both ways: the point observes this keyframe at this keypoint (an erased keyframe
			// observes nothing).
			const auto o = it->second.observations.find(id);
			if (kf->bad || o == it->second.observations.end() || o->second != i)
				throw std::runtime_error("keyframe map point not observed back reading map");
		}
		if (kf->parent && !known(*kf->parent)) throw std::runtime_error("keyframe parent unknown reading map");
		// The spanning tree both ways among the good keyframes (an erased one keeps its parent for
		// its pose but is no longer its child, and has no children).
		if (!kf->bad && kf->parent && (kfs.at(*kf->parent)->bad || !kfs.at(*kf->parent)->children.count(id)))
			throw std::runtime_error("keyframe parent does not list it as a child reading map");
		for (TKeyFrameId c : kf->children)
			if (kf->bad || !known(c) || kfs.at(c)->bad || kfs.at(c)->parent != std::optional<TKeyFrameId>(id))
				throw std::runtime_error("keyframe child unknown or with another parent reading map");
		for (const auto& [o, w] : kf->connections)
			if (!known(o)) throw std::runtime_error("keyframe connection unknown reading map");
		for (TKeyFrameId e : kf->loopEdges)
			if (!known(e)) throw std::runtime_error("keyframe loop edge unknown reading map");
	}
	if (!kfs.empty() && kfs.begin()->second->bad) throw std::runtime_error("the first keyframe is erased reading map");
	// Poses and positions finite, and every parent chain ends (poses of erased keyframes follow it).
	const auto finite = [](const mrpt::poses::CPose3D& p)
	{
		const auto M = p.getHomogeneousMatrixVal<mrpt::math::CMatrixDouble44>();
		for (int r = 0; r < 3; r++)
			for (int c = 0; c < 4; c++)
				if (!std::isfinite(M(r, c))) return false;
		return true;
	};
	for (const auto& [id, kf] : kfs)
	{
		if (!finite(kf->pose) || !finite(kf->poseInParent))
			throw std::runtime_error("keyframe pose not finite reading map");
		TKeyFrameId at = id;
		for (std::size_t hops = 0; kfs.at(at)->parent; hops++)
		{
			if (hops > kfs.size()) throw std::runtime_error("the spanning tree has a cycle reading map");
			at = *kfs.at(at)->parent;
		}
	}
	for (const auto& [id, p] : pts)
		if (!std::isfinite(p.position.x) || !std::isfinite(p.position.y) || !std::isfinite(p.position.z))
			throw std::runtime_error("map point position not finite reading map");
	auto s = std::make_unique<TSparseMapStore>();
	s->keyFrames = std::move(kfs);
	s->points = std::move(pts);
	s->numGoodKeyFrames = goodKfs;
	s->numGoodPoints = s->points.size();
	s->nextKeyFrame = nextKf;
	s->nextPoint = nextPt;
	s->generation = gen;
	// Tracking's local map, local BA's window, culling and the essential graph all read the
	// weights: they are recounted from the observations just validated, never taken on trust.
	s->rebuildConnections();
	return s;
}

}  // namespace mrpt_yesslam::sparse_map
