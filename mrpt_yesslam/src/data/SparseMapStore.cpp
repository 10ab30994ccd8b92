#include "SparseMapStore.h"

#include <algorithm>
#include <unordered_set>

namespace mrpt_yesslam
{
namespace
{
// A bad point stays resolvable (a fused one through replacedBy) until this many keyframes have been
// inserted after it went bad, then it is forgotten; whatever still names it then (a long global BA's
// window, an old buffered frame) finds nothing and skips it, as it skips any bad point. Keeping every point ever made
// grew the table without bound (a 3000-frame run held 28,061 dead points beside 4,814 live ones) and made every lookup
// of tracking's local map slower as the run went on (ORB-SLAM2 never frees them at all).
constexpr TKeyFrameId kForgetBadPointsAfter = 3;
}  // namespace

void TSparseMapStore::appendPoint(TLocalMapPoints& out, const CMapPoint& p) const
{
	out.ids.push_back(p.id);
	out.positions.push_back(p.position);
	out.descriptors.push_back(p.descriptor);
	// How it has been seen (ORB-SLAM2's MapPoint::UpdateNormalAndDepth), from its observations as
	// they are now: kept in step with every keyframe added, erased, moved or corrected, at the cost
	// of a few lookups per observation (tracking copies a few thousand points a frame).
	mrpt::math::TPoint3D n(0, 0, 0);
	float refDistance = 0;
	int refOctave = 0;
	bool haveRef = false;
	for (const auto& [k, kp] : p.observations)
	{
		const auto it = keyFrames.find(k);
		if (it == keyFrames.end() || it->second->bad) continue;
		const CKeyFrame& kf = *it->second;
		const mrpt::math::TPoint3D d(p.position.x - kf.pose.x(), p.position.y - kf.pose.y(),
									 p.position.z - kf.pose.z());
		const double len = d.norm();
		if (!(len > 0)) continue;
		n += d * (1.0 / len);
		// The reference keyframe: the one that made the point while it observes it, else the first.
		if (!haveRef || k == p.firstKeyFrame)
		{
			refDistance = static_cast<float>(len);
			refOctave = kp < kf.size() ? kf.features->keypoints[kp].octave : 0;
			haveRef = true;
		}
	}
	const double nl = n.norm();
	out.normals.push_back(nl > 0 ? n * (1.0 / nl) : n);
	out.refDistances.push_back(refDistance);
	out.refOctaves.push_back(refOctave);
}

TKeyFrameId TSparseMapStore::addKeyFrame(const TFrame& frame, double maxDepth, std::size_t* newPoints)
{
	forgetDeadPoints();
	auto kfp = std::make_shared<CKeyFrame>();
	CKeyFrame& kf = *kfp;
	kf.id = nextKeyFrame++;
	kf.frameId = frame.id;
	kf.timestamp = frame.timestamp;
	kf.camera = frame.camera;
	kf.features = std::make_shared<const TFeatures>(frame.features);
	kf.colors = frame.colors;
	kf.detections = frame.detections;
	kf.pose = frame.pose;
	kf.mapPoints.assign(frame.size(), -1);
	keyFrames.emplace(kf.id, kfp);
	numGoodKeyFrames++;
	std::size_t created = 0;
	for (std::size_t i = 0; i < frame.size(); i++)
	{
		const TPointId matched = i < frame.mapPoints.size() ? frame.mapPoints[i] : -1;
		if (matched >= 0)
		{
			// Tracking may have matched a point that has since been fused: follow it.
			const CMapPoint* gp = goodPoint(matched);
			if (gp && !gp->observations.count(kf.id))
			{
				addObservation(points.at(gp->id), kf, i);
				continue;
			}
		}
		// A keypoint the mask was unsure of never starts a map point (CGeometricDynamicCheck).
		if (!frame.usable(i, maxDepth) || frame.features.isUncertain(i)) continue;
		const cv::Point3d pc = frame.backProject(i);
		CMapPoint p;
		p.id = nextPoint++;
		double gx, gy, gz;
		frame.pose.composePoint(pc.x, pc.y, pc.z, gx, gy, gz);
		p.position = {gx, gy, gz};
		p.descriptor = frame.features.descriptors.row(static_cast<int>(i)).clone();
		p.color = i < frame.colors.size() ? frame.colors[i] : cv::Vec3b(128, 128, 128);
		p.firstKeyFrame = kf.id;
		CMapPoint& stored = points.emplace(p.id, std::move(p)).first->second;
		addObservation(stored, kf, i);
		recent.push_back(stored.id);
		numGoodPoints++;
		created++;
	}
	reorderDirty();
	// Spanning tree: the parent is the keyframe sharing most points (ORB-SLAM2's UpdateConnections);
	// a keyframe sharing none (after a loss) hangs under the newest good one, so the tree stays one tree.
	if (!kf.orderedConnections.empty())
		kf.parent = kf.orderedConnections.front();
	else
		for (auto it = std::next(keyFrames.rbegin()); it != keyFrames.rend(); ++it)
			if (!it->second->bad)
			{
				kf.parent = it->first;
				break;
			}
	if (kf.parent) keyFrames.at(*kf.parent)->children.insert(kf.id);
	if (newPoints) *newPoints = created;
	return kf.id;
}

void TSparseMapStore::addObservation(CMapPoint& p, CKeyFrame& kf, std::size_t kp)
{
	// Every keyframe already observing the point gains one shared point with `kf`.
	for (const auto& [other, idx] : p.observations)
	{
		if (other == kf.id) continue;
		auto it = keyFrames.find(other);
		if (it == keyFrames.end() || it->second->bad) continue;
		kf.connections[other]++;
		it->second->connections[kf.id]++;
		dirty.push_back(other);
	}
	dirty.push_back(kf.id);
	p.observations[kf.id] = kp;
	kf.mapPoints[kp] = p.id;
}

void TSparseMapStore::eraseObservation(CMapPoint& p, TKeyFrameId kfId)
{
	const auto it = p.observations.find(kfId);
	if (it == p.observations.end()) return;
	const auto kit = keyFrames.find(kfId);
	if (kit != keyFrames.end())
	{
		CKeyFrame& kf = *kit->second;
		if (it->second < kf.mapPoints.size() && kf.mapPoints[it->second] == p.id) kf.mapPoints[it->second] = -1;
		for (const auto& [other, idx] : p.observations)
		{
			if (other == kfId) continue;
			auto ot = keyFrames.find(other);
			if (ot == keyFrames.end()) continue;
			for (auto [a, b] : {std::pair<CKeyFrame*, TKeyFrameId>{&kf, other}, {ot->second.get(), kfId}})
			{
				auto c = a->connections.find(b);
				if (c != a->connections.end() && --c->second <= 0) a->connections.erase(c);
			}
			dirty.push_back(other);
		}
		dirty.push_back(kfId);
	}
	p.observations.erase(it);
}

void TSparseMapStore::reorderDirty()
{
	std::sort(dirty.begin(), dirty.end());
	dirty.erase(std::unique(dirty.begin(), dirty.end()), dirty.end());
	for (TKeyFrameId id : dirty)
	{
		auto it = keyFrames.find(id);
		if (it == keyFrames.end()) continue;
		CKeyFrame& kf = *it->second;
		kf.orderedConnections.clear();
		for (const auto& [k, w] : kf.connections) kf.orderedConnections.push_back(k);
		// Heaviest first; ties by id (older first) so that the order, and everything built on it,
		// is deterministic.
		std::stable_sort(kf.orderedConnections.begin(), kf.orderedConnections.end(),
						 [&](TKeyFrameId a, TKeyFrameId b) { return kf.connections.at(a) > kf.connections.at(b); });
	}
	dirty.clear();
}

void TSparseMapStore::rebuildConnections()
{
	for (auto& [id, kf] : keyFrames)
	{
		kf->connections.clear();
		dirty.push_back(id);
	}
	for (const auto& [pid, p] : points)
	{
		if (p.bad) continue;
		for (const auto& [a, ia] : p.observations)
			for (const auto& [b, ib] : p.observations)
			{
				if (a == b) continue;
				const auto ka = keyFrames.find(a), kb = keyFrames.find(b);
				if (ka != keyFrames.end() && kb != keyFrames.end() && !ka->second->bad && !kb->second->bad)
					ka->second->connections[b]++;
			}
	}
	reorderDirty();
}

void TSparseMapStore::markBad(CMapPoint& p)
{
	p.bad = true;
	numGoodPoints--;
	dead.emplace_back(nextKeyFrame, p.id);
}

void TSparseMapStore::dropPoint(CMapPoint& p)
{
	markBad(p);
	const auto obs = p.observations;
	for (const auto& [k, kp] : obs) eraseObservation(p, k);
}

void TSparseMapStore::forgetDeadPoints()
{
	while (!dead.empty() && dead.front().first + kForgetBadPointsAfter <= nextKeyFrame)
	{
		const auto it = points.find(dead.front().second);
		if (it != points.end() && it->second.bad) points.erase(it);
		dead.pop_front();
	}
}

const CMapPoint* TSparseMapStore::goodPoint(TPointId id) const
{
	// A fused point is followed to the point that took its observations (a short chain).
	for (int hops = 0; hops < 8 && id >= 0; hops++)
	{
		const auto it = points.find(id);
		if (it == points.end()) return nullptr;
		if (!it->second.bad) return &it->second;
		id = it->second.replacedBy;
	}
	return nullptr;
}

mrpt::poses::CPose3D TSparseMapStore::pose(TKeyFrameId id) const
{
	// A bad keyframe's pose follows its parent (ORB-SLAM2 saves trajectories this way), so frames
	// tracked from an erased keyframe still move with the corrected map.
	mrpt::poses::CPose3D rel;
	for (std::size_t hops = 0; hops <= keyFrames.size(); hops++)
	{
		const CKeyFrame& kf = *keyFrames.at(id);
		if (!kf.bad) return kf.pose + rel;
		if (!kf.parent) return kf.pose + rel;
		rel = kf.poseInParent + rel;
		id = *kf.parent;
	}
	throw std::logic_error("CSparseMap: cycle in the spanning tree");
}

std::vector<TKeyFrameId> TSparseMapStore::covisible(TKeyFrameId id, std::size_t max, int minWeight) const
{
	std::vector<TKeyFrameId> out;
	const auto it = keyFrames.find(id);
	if (it == keyFrames.end()) return out;
	const CKeyFrame& kf = *it->second;
	for (TKeyFrameId k : kf.orderedConnections)
	{
		if (out.size() >= max || kf.connections.at(k) < minWeight) break;
		out.push_back(k);
	}
	return out;
}

TKeyFrameId TSparseMapStore::goodAncestor(TKeyFrameId id) const
{
	for (std::size_t hops = 0; hops <= keyFrames.size(); hops++)
	{
		const CKeyFrame& kf = *keyFrames.at(id);
		if (!kf.bad || !kf.parent) return id;
		id = *kf.parent;
	}
	throw std::logic_error("CSparseMap: cycle in the spanning tree");
}

TLocalMapPoints TSparseMapStore::pointsOfKeyFrames(const std::vector<TKeyFrameId>& ids) const
{
	TLocalMapPoints out;
	std::unordered_set<TPointId> seen;
	for (TKeyFrameId k : ids)
	{
		const auto it = keyFrames.find(k);
		if (it == keyFrames.end() || it->second->bad) continue;
		for (TPointId pid : it->second->mapPoints)
		{
			if (pid < 0 || !seen.insert(pid).second) continue;
			if (const CMapPoint* p = goodPoint(pid)) appendPoint(out, *p);
		}
	}
	return out;
}

bool TSparseMapStore::replacePoint(TPointId oldId, TPointId newId)
{
	if (oldId == newId) return false;
	auto oit = points.find(oldId), nit = points.find(newId);
	if (oit == points.end() || nit == points.end() || oit->second.bad || nit->second.bad) return false;
	CMapPoint& oldP = oit->second;
	CMapPoint& newP = nit->second;
	const auto obs = oldP.observations;
	for (const auto& [k, kp] : obs)
	{
		eraseObservation(oldP, k);
		auto kit = keyFrames.find(k);
		if (kit == keyFrames.end() || kit->second->bad) continue;
		// A keyframe that sees both keeps its observation of the new point (ORB-SLAM2's Replace).
		if (!newP.observations.count(k)) addObservation(newP, *kit->second, kp);
	}
	newP.visible += oldP.visible;
	newP.found += oldP.found;
	markBad(oldP);
	oldP.replacedBy = newId;
	return true;
}

std::size_t TSparseMapStore::fuse(const std::vector<TFuseCandidate>& candidates)
{
	std::size_t changed = 0;
	for (const auto& c : candidates)
	{
		const CMapPoint* gp = goodPoint(c.point);
		auto kit = keyFrames.find(c.keyFrame);
		if (!gp || kit == keyFrames.end() || kit->second->bad) continue;
		CKeyFrame& kf = *kit->second;
		if (c.keypoint >= kf.mapPoints.size() || gp->observations.count(kf.id)) continue;
		const TPointId pid = gp->id;
		const CMapPoint* existing = kf.mapPoints[c.keypoint] >= 0 ? goodPoint(kf.mapPoints[c.keypoint]) : nullptr;
		if (existing)
		{
			if (existing->id == pid) continue;
			// The better-observed point survives (ORB-SLAM2 keeps the one seen more often).
			const bool keepExisting = existing->observations.size() >= gp->observations.size();
			changed += keepExisting ? replacePoint(pid, existing->id) : replacePoint(existing->id, pid);
		}
		else
		{
			kf.mapPoints[c.keypoint] = -1;
			addObservation(points.at(pid), kf, c.keypoint);
			changed++;
		}
	}
	reorderDirty();
	return changed;
}

void TSparseMapStore::eraseKeyFrame(CKeyFrame& kf)
{
	// ORB-SLAM2's KeyFrame::SetBadFlag: drop the observations, then re-hang the children in the
	// spanning tree, each under the candidate (the parent, or a child already re-hung) it shares
	// most points with; children that share none with any candidate go to the parent.
	for (std::size_t i = 0; i < kf.mapPoints.size(); i++)
	{
		const TPointId pid = kf.mapPoints[i];
		if (pid < 0) continue;
		auto it = points.find(pid);
		if (it == points.end()) continue;
		eraseObservation(it->second, kf.id);
		if (!it->second.bad && it->second.observations.empty()) markBad(it->second);
	}
	reorderDirty();
	const TKeyFrameId parent = *kf.parent;
	std::set<TKeyFrameId> candidates{parent};
	std::set<TKeyFrameId> children = kf.children;
	while (!children.empty())
	{
		int best = 0;
		TKeyFrameId bestChild = 0, bestParent = 0;
		for (TKeyFrameId c : children)
		{
			const CKeyFrame& ck = *keyFrames.at(c);
			for (TKeyFrameId cand : candidates)
				if (const int w = ck.weight(cand); w > best)
				{
					best = w;
					bestChild = c;
					bestParent = cand;
				}
		}
		if (best == 0) break;
		CKeyFrame& ck = *keyFrames.at(bestChild);
		ck.parent = bestParent;
		keyFrames.at(bestParent)->children.insert(bestChild);
		candidates.insert(bestChild);
		children.erase(bestChild);
	}
	for (TKeyFrameId c : children)
	{
		keyFrames.at(c)->parent = parent;
		keyFrames.at(parent)->children.insert(c);
	}
	kf.children.clear();
	keyFrames.at(parent)->children.erase(kf.id);
	kf.poseInParent = kf.pose - keyFrames.at(parent)->pose;
	kf.bad = true;
	kf.connections.clear();
	kf.orderedConnections.clear();
	// The measurements are what costs memory; a bad keyframe keeps only what resolves its pose.
	kf.features.reset();
	kf.bow.reset();
	kf.colors.clear();
	kf.colors.shrink_to_fit();
	kf.mapPoints.clear();
	kf.mapPoints.shrink_to_fit();
	numGoodKeyFrames--;
}

void TSparseMapStore::eraseOutliers(const std::vector<std::pair<TPointId, TKeyFrameId>>& outliers)
{
	for (const auto& [pid, k] : outliers)
	{
		auto it = points.find(pid);
		if (it == points.end() || it->second.bad) continue;
		eraseObservation(it->second, k);
		if (it->second.observations.empty()) markBad(it->second);
	}
	reorderDirty();
}

}  // namespace mrpt_yesslam
