#include "mrpt_yesslam/data/CSparseMap.h"

#include <Eigen/Geometry>

#include "mrpt_yesslam/util/BinaryIO.h"

#include <algorithm>
#include <cmath>
#include <mutex>
#include <set>
#include <stdexcept>
#include <unordered_set>

namespace mrpt_yesslam
{
using ReadLock = std::shared_lock<std::shared_mutex>;
using WriteLock = std::unique_lock<std::shared_mutex>;

namespace
{
// Points created by one keyframe stay on the recent list for this many further keyframes
// (ORB-SLAM2's MapPointCulling judges a point until three keyframes after its creation).
constexpr TKeyFrameId kRecentKeyFrames = 3;
// A bad point stays resolvable (a fused one through replacedBy) until this many keyframes have been
// inserted after it went bad, then it is forgotten; whatever still names it then (a long global BA's
// window, an old buffered frame) finds nothing and skips it, as it skips any bad point. Keeping every point ever made grew the table without bound (a 3000-frame
// run held 28,061 dead points beside 4,814 live ones) and made every lookup of tracking's local map
// slower as the run went on (ORB-SLAM2 never frees them at all).
constexpr TKeyFrameId kForgetBadPointsAfter = 3;

void appendPoint(TLocalMapPoints& out, const CMapPoint& p)
{
	out.ids.push_back(p.id);
	out.positions.push_back(p.position);
	out.descriptors.push_back(p.descriptor);
}
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

// ---------------------------------------------------------------------------------------------
// Internal bookkeeping (map lock held by the caller)

void CSparseMap::addObservation(CMapPoint& p, CKeyFrame& kf, std::size_t kp)
{
	// Every keyframe already observing the point gains one shared point with `kf`.
	for (const auto& [other, idx] : p.observations)
	{
		if (other == kf.id) continue;
		auto it = keyFrames_.find(other);
		if (it == keyFrames_.end() || it->second->bad) continue;
		kf.connections[other]++;
		it->second->connections[kf.id]++;
		dirty_.push_back(other);
	}
	dirty_.push_back(kf.id);
	p.observations[kf.id] = kp;
	kf.mapPoints[kp] = p.id;
}

void CSparseMap::eraseObservation(CMapPoint& p, TKeyFrameId kfId)
{
	const auto it = p.observations.find(kfId);
	if (it == p.observations.end()) return;
	const auto kit = keyFrames_.find(kfId);
	if (kit != keyFrames_.end())
	{
		CKeyFrame& kf = *kit->second;
		if (it->second < kf.mapPoints.size() && kf.mapPoints[it->second] == p.id) kf.mapPoints[it->second] = -1;
		for (const auto& [other, idx] : p.observations)
		{
			if (other == kfId) continue;
			auto ot = keyFrames_.find(other);
			if (ot == keyFrames_.end()) continue;
			for (auto [a, b] : {std::pair<CKeyFrame*, TKeyFrameId>{&kf, other}, {ot->second.get(), kfId}})
			{
				auto c = a->connections.find(b);
				if (c != a->connections.end() && --c->second <= 0) a->connections.erase(c);
			}
			dirty_.push_back(other);
		}
		dirty_.push_back(kfId);
	}
	p.observations.erase(it);
}

void CSparseMap::reorderDirty()
{
	std::sort(dirty_.begin(), dirty_.end());
	dirty_.erase(std::unique(dirty_.begin(), dirty_.end()), dirty_.end());
	for (TKeyFrameId id : dirty_)
	{
		auto it = keyFrames_.find(id);
		if (it == keyFrames_.end()) continue;
		CKeyFrame& kf = *it->second;
		kf.orderedConnections.clear();
		for (const auto& [k, w] : kf.connections) kf.orderedConnections.push_back(k);
		// Heaviest first; ties by id (older first) so that the order, and everything built on it,
		// is deterministic.
		std::stable_sort(kf.orderedConnections.begin(), kf.orderedConnections.end(),
						 [&](TKeyFrameId a, TKeyFrameId b) { return kf.connections.at(a) > kf.connections.at(b); });
	}
	dirty_.clear();
}

void CSparseMap::markBadLocked(CMapPoint& p)
{
	p.bad = true;
	numGoodPoints_--;
	dead_.emplace_back(nextKeyFrame_, p.id);
}

void CSparseMap::forgetDeadPointsLocked()
{
	while (!dead_.empty() && dead_.front().first + kForgetBadPointsAfter <= nextKeyFrame_)
	{
		const auto it = points_.find(dead_.front().second);
		if (it != points_.end() && it->second.bad) points_.erase(it);
		dead_.pop_front();
	}
}

const CMapPoint* CSparseMap::goodPoint(TPointId id) const
{
	// A fused point is followed to the point that took its observations (a short chain).
	for (int hops = 0; hops < 8 && id >= 0; hops++)
	{
		const auto it = points_.find(id);
		if (it == points_.end()) return nullptr;
		if (!it->second.bad) return &it->second;
		id = it->second.replacedBy;
	}
	return nullptr;
}

mrpt::poses::CPose3D CSparseMap::poseLocked(TKeyFrameId id) const
{
	// A bad keyframe's pose follows its parent (ORB-SLAM2 saves trajectories this way), so frames
	// tracked from an erased keyframe still move with the corrected map.
	mrpt::poses::CPose3D rel;
	for (std::size_t hops = 0; hops <= keyFrames_.size(); hops++)
	{
		const CKeyFrame& kf = *keyFrames_.at(id);
		if (!kf.bad) return kf.pose + rel;
		if (!kf.parent) return kf.pose + rel;
		rel = kf.poseInParent + rel;
		id = *kf.parent;
	}
	throw std::logic_error("CSparseMap: cycle in the spanning tree");
}

std::vector<TKeyFrameId> CSparseMap::covisibleLocked(TKeyFrameId id, std::size_t max, int minWeight) const
{
	std::vector<TKeyFrameId> out;
	const auto it = keyFrames_.find(id);
	if (it == keyFrames_.end()) return out;
	const CKeyFrame& kf = *it->second;
	for (TKeyFrameId k : kf.orderedConnections)
	{
		if (out.size() >= max || kf.connections.at(k) < minWeight) break;
		out.push_back(k);
	}
	return out;
}

// ---------------------------------------------------------------------------------------------

TKeyFrameId CSparseMap::addKeyFrame(const std::shared_ptr<const TFrame>& frame, double maxDepth, std::size_t* newPoints)
{
	WriteLock lk(mtx_);
	forgetDeadPointsLocked();
	auto kfp = std::make_shared<CKeyFrame>();
	CKeyFrame& kf = *kfp;
	kf.id = nextKeyFrame_++;
	kf.frameId = frame->id;
	kf.timestamp = frame->timestamp;
	kf.camera = frame->camera;
	kf.features = std::make_shared<const TFeatures>(frame->features);
	kf.colors = frame->colors;
	kf.detections = frame->detections;
	kf.pose = frame->pose;
	kf.mapPoints.assign(frame->size(), -1);
	keyFrames_.emplace(kf.id, kfp);
	numGoodKeyFrames_++;
	std::size_t created = 0;
	for (std::size_t i = 0; i < frame->size(); i++)
	{
		const TPointId matched = i < frame->mapPoints.size() ? frame->mapPoints[i] : -1;
		if (matched >= 0)
		{
			// Tracking may have matched a point that has since been fused: follow it.
			const CMapPoint* gp = goodPoint(matched);
			if (gp && !gp->observations.count(kf.id))
			{
				addObservation(points_.at(gp->id), kf, i);
				continue;
			}
		}
		// A keypoint the mask was unsure of never starts a map point (CGeometricDynamicCheck).
		if (!frame->usable(i, maxDepth) || frame->features.isUncertain(i)) continue;
		const cv::Point3d pc = frame->backProject(i);
		CMapPoint p;
		p.id = nextPoint_++;
		double gx, gy, gz;
		frame->pose.composePoint(pc.x, pc.y, pc.z, gx, gy, gz);
		p.position = {gx, gy, gz};
		p.descriptor = frame->features.descriptors.row(static_cast<int>(i)).clone();
		p.color = i < frame->colors.size() ? frame->colors[i] : cv::Vec3b(128, 128, 128);
		p.firstKeyFrame = kf.id;
		CMapPoint& stored = points_.emplace(p.id, std::move(p)).first->second;
		addObservation(stored, kf, i);
		recent_.push_back(stored.id);
		numGoodPoints_++;
		created++;
	}
	reorderDirty();
	// Spanning tree: the parent is the keyframe sharing most points (ORB-SLAM2's UpdateConnections);
	// a keyframe sharing none (after a loss) hangs under the newest good one, so the tree stays one tree.
	if (!kf.orderedConnections.empty())
		kf.parent = kf.orderedConnections.front();
	else
		for (auto it = std::next(keyFrames_.rbegin()); it != keyFrames_.rend(); ++it)
			if (!it->second->bad)
			{
				kf.parent = it->first;
				break;
			}
	if (kf.parent) keyFrames_.at(*kf.parent)->children.insert(kf.id);
	if (newPoints) *newPoints = created;
	return kf.id;
}

bool CSparseMap::setKeyFrameBow(TKeyFrameId id, std::shared_ptr<const TBow> bow)
{
	WriteLock lk(mtx_);
	const auto it = keyFrames_.find(id);
	if (it == keyFrames_.end() || it->second->bad) return false;
	it->second->bow = std::move(bow);
	return true;
}

std::size_t CSparseMap::numKeyFrames() const
{
	ReadLock lk(mtx_);
	return numGoodKeyFrames_;
}

std::vector<TKeyFrameId> CSparseMap::keyFrameIds() const
{
	ReadLock lk(mtx_);
	std::vector<TKeyFrameId> out;
	for (const auto& [id, kf] : keyFrames_)
		if (!kf->bad) out.push_back(id);
	return out;
}

bool CSparseMap::hasKeyFrame(TKeyFrameId id) const
{
	ReadLock lk(mtx_);
	return keyFrames_.count(id) != 0;
}

bool CSparseMap::isBad(TKeyFrameId id) const
{
	ReadLock lk(mtx_);
	return keyFrames_.at(id)->bad;
}

TKeyFrameId CSparseMap::goodAncestor(TKeyFrameId id) const
{
	ReadLock lk(mtx_);
	return goodAncestorLocked(id);
}

TKeyFrameId CSparseMap::goodAncestorLocked(TKeyFrameId id) const
{
	for (std::size_t hops = 0; hops <= keyFrames_.size(); hops++)
	{
		const CKeyFrame& kf = *keyFrames_.at(id);
		if (!kf.bad || !kf.parent) return id;
		id = *kf.parent;
	}
	throw std::logic_error("CSparseMap: cycle in the spanning tree");
}

std::size_t CSparseMap::numPoints() const
{
	ReadLock lk(mtx_);
	return numGoodPoints_;
}

mrpt::poses::CPose3D CSparseMap::keyFramePose(TKeyFrameId id) const
{
	ReadLock lk(mtx_);
	return poseLocked(id);
}

CKeyFrame CSparseMap::keyFrame(TKeyFrameId id) const
{
	ReadLock lk(mtx_);
	return *keyFrames_.at(id);
}

CMapPoint CSparseMap::point(TPointId id) const
{
	ReadLock lk(mtx_);
	if (const auto it = points_.find(id); it != points_.end()) return it->second;
	if (id < 0 || id >= nextPoint_) throw std::out_of_range("CSparseMap: no map point " + std::to_string(id));
	CMapPoint forgotten;  // erased long enough ago to be forgotten: all that is left is that it is bad
	forgotten.id = id;
	forgotten.bad = true;
	return forgotten;
}

std::size_t CSparseMap::numStoredPoints() const
{
	ReadLock lk(mtx_);
	return points_.size();
}

std::vector<TKeyFrameId> CSparseMap::covisible(TKeyFrameId id, std::size_t max, int minWeight) const
{
	ReadLock lk(mtx_);
	return covisibleLocked(id, max, minWeight);
}

TLocalMapPoints CSparseMap::pointsOfKeyFrames(const std::vector<TKeyFrameId>& ids) const
{
	ReadLock lk(mtx_);
	return pointsOfKeyFramesLocked(ids);
}

TLocalMapPoints CSparseMap::pointsOfKeyFramesLocked(const std::vector<TKeyFrameId>& ids) const
{
	TLocalMapPoints out;
	std::unordered_set<TPointId> seen;
	for (TKeyFrameId k : ids)
	{
		const auto it = keyFrames_.find(k);
		if (it == keyFrames_.end() || it->second->bad) continue;
		for (TPointId pid : it->second->mapPoints)
		{
			if (pid < 0 || !seen.insert(pid).second) continue;
			if (const CMapPoint* p = goodPoint(pid)) appendPoint(out, *p);
		}
	}
	return out;
}

std::vector<TKeyFrameId> CSparseMap::localKeyFrames(
	const std::vector<TPointId>& seeds, TKeyFrameId fallback, std::size_t maxKeyFrames, std::size_t neighbours) const
{
	ReadLock lk(mtx_);
	std::unordered_map<TKeyFrameId, int> shared;
	for (TPointId pid : seeds)
		if (const CMapPoint* p = goodPoint(pid))
			for (const auto& [k, kp] : p->observations)
				if (!keyFrames_.at(k)->bad) shared[k]++;
	// Most shared first; ties to the newer keyframe (closer in time to the frame).
	std::vector<std::pair<int, TKeyFrameId>> order;
	for (const auto& [k, n] : shared) order.emplace_back(n, k);
	std::sort(order.begin(), order.end(), [](const auto& a, const auto& b) { return a.first != b.first ? a.first > b.first : a.second > b.second; });
	std::vector<TKeyFrameId> out;
	std::unordered_set<TKeyFrameId> in;
	const auto add = [&](TKeyFrameId k) {
		if (out.size() >= maxKeyFrames || in.count(k)) return;
		const auto it = keyFrames_.find(k);
		if (it == keyFrames_.end() || it->second->bad) return;
		in.insert(k);
		out.push_back(k);
	};
	for (const auto& [n, k] : order) add(k);
	if (out.empty())
		if (keyFrames_.count(fallback)) add(goodAncestorLocked(fallback));
	// K2: around the keyframes that share points with the frame (ORB-SLAM2 takes 10 covisible,
	// one child and the parent of each; all children here, the tree is shallow in our maps).
	const std::size_t k1 = out.size();
	for (std::size_t i = 0; i < k1 && out.size() < maxKeyFrames; i++)
	{
		const CKeyFrame& kf = *keyFrames_.at(out[i]);
		for (TKeyFrameId n : covisibleLocked(kf.id, neighbours, 1)) add(n);
		for (TKeyFrameId c : kf.children) add(c);
		if (kf.parent) add(*kf.parent);
	}
	return out;
}

TLocalMapPoints CSparseMap::keyFramePoints(TKeyFrameId id, std::vector<std::size_t>* keypoints) const
{
	ReadLock lk(mtx_);
	TLocalMapPoints out;
	if (keypoints) keypoints->clear();
	const auto it = keyFrames_.find(id);
	if (it == keyFrames_.end()) return out;
	const auto& kf = *it->second;
	for (std::size_t i = 0; i < kf.mapPoints.size(); i++)
	{
		if (kf.mapPoints[i] < 0) continue;
		const auto pit = points_.find(kf.mapPoints[i]);
		if (pit == points_.end() || pit->second.bad) continue;
		appendPoint(out, pit->second);
		if (keypoints) keypoints->push_back(i);
	}
	return out;
}

std::size_t CSparseMap::numKeyFramePoints(TKeyFrameId id, std::size_t minObservations) const
{
	ReadLock lk(mtx_);
	const auto it = keyFrames_.find(id);
	if (it == keyFrames_.end()) return 0;
	std::size_t n = 0;
	for (TPointId pid : it->second->mapPoints)
		if (pid >= 0)
			if (auto pit = points_.find(pid); pit != points_.end() && !pit->second.bad && pit->second.observations.size() >= minObservations)
				n++;
	return n;
}

TLocalMapPoints CSparseMap::pointsById(const std::vector<TPointId>& ids) const
{
	ReadLock lk(mtx_);
	TLocalMapPoints out;
	for (TPointId id : ids)
		if (const CMapPoint* p = goodPoint(id)) appendPoint(out, *p);
	return out;
}

std::size_t CSparseMap::countTracking(
	const std::vector<TPointId>& visible, const std::vector<TPointId>& found, const std::vector<TPointId>& seenThrough,
	int seeThroughFrames)
{
	WriteLock lk(mtx_);
	for (TPointId id : visible)
		if (auto it = points_.find(id); it != points_.end()) it->second.visible++;
	for (TPointId id : found)
		if (auto it = points_.find(id); it != points_.end())
		{
			it->second.found++;
			it->second.seenThrough = 0;
		}
	std::size_t erased = 0;
	for (TPointId id : seenThrough)
	{
		auto it = points_.find(id);
		if (it == points_.end() || it->second.bad) continue;
		CMapPoint& p = it->second;
		if (seeThroughFrames <= 0 || ++p.seenThrough < seeThroughFrames) continue;
		markBadLocked(p);
		const auto obs = p.observations;
		for (const auto& [k, kp] : obs) eraseObservation(p, k);
		erased++;
	}
	if (erased) reorderDirty();
	return erased;
}

std::size_t CSparseMap::cullRecentPoints(TKeyFrameId currentKf, double minFoundRatio, std::size_t minObservations)
{
	WriteLock lk(mtx_);
	std::size_t culled = 0;
	std::deque<TPointId> keep;
	for (TPointId id : recent_)
	{
		auto it = points_.find(id);
		if (it == points_.end() || it->second.bad) continue;  // already gone: leaves the list
		CMapPoint& p = it->second;
		const double ratio = static_cast<double>(p.found) / std::max(1, p.visible);
		const bool tooRare = ratio < minFoundRatio;
		const bool tooFewViews = currentKf >= p.firstKeyFrame + 2 && p.observations.size() < minObservations;
		if (tooRare || tooFewViews)
		{
			markBadLocked(p);
			const auto obs = p.observations;
			for (const auto& [k, kp] : obs) eraseObservation(p, k);
			culled++;
			continue;
		}
		// Survived its trial period: a grown-up point, no longer judged (ORB-SLAM2).
		if (currentKf < p.firstKeyFrame + kRecentKeyFrames) keep.push_back(id);
	}
	recent_.swap(keep);
	reorderDirty();
	return culled;
}

std::size_t CSparseMap::numRecentPoints() const
{
	ReadLock lk(mtx_);
	return recent_.size();
}

bool CSparseMap::erasePoint(TPointId id)
{
	WriteLock lk(mtx_);
	auto it = points_.find(id);
	if (it == points_.end() || it->second.bad) return false;
	markBadLocked(it->second);
	const auto obs = it->second.observations;
	for (const auto& [k, kp] : obs) eraseObservation(it->second, k);
	reorderDirty();
	return true;
}

bool CSparseMap::replacePoint(TPointId oldId, TPointId newId)
{
	WriteLock lk(mtx_);
	const bool ok = replacePointLocked(oldId, newId);
	reorderDirty();
	return ok;
}

std::size_t CSparseMap::fuse(const std::vector<TFuseCandidate>& candidates)
{
	WriteLock lk(mtx_);
	std::size_t changed = 0;
	for (const auto& c : candidates)
	{
		const CMapPoint* gp = goodPoint(c.point);
		auto kit = keyFrames_.find(c.keyFrame);
		if (!gp || kit == keyFrames_.end() || kit->second->bad) continue;
		CKeyFrame& kf = *kit->second;
		if (c.keypoint >= kf.mapPoints.size() || gp->observations.count(kf.id)) continue;
		const TPointId pid = gp->id;
		const CMapPoint* existing = kf.mapPoints[c.keypoint] >= 0 ? goodPoint(kf.mapPoints[c.keypoint]) : nullptr;
		if (existing)
		{
			if (existing->id == pid) continue;
			// The better-observed point survives (ORB-SLAM2 keeps the one seen more often).
			const bool keepExisting = existing->observations.size() >= gp->observations.size();
			changed += keepExisting ? replacePointLocked(pid, existing->id) : replacePointLocked(existing->id, pid);
		}
		else
		{
			kf.mapPoints[c.keypoint] = -1;
			addObservation(points_.at(pid), kf, c.keypoint);
			changed++;
		}
	}
	reorderDirty();
	return changed;
}

bool CSparseMap::replacePointLocked(TPointId oldId, TPointId newId)
{
	if (oldId == newId) return false;
	auto oit = points_.find(oldId), nit = points_.find(newId);
	if (oit == points_.end() || nit == points_.end() || oit->second.bad || nit->second.bad) return false;
	CMapPoint& oldP = oit->second;
	CMapPoint& newP = nit->second;
	const auto obs = oldP.observations;
	for (const auto& [k, kp] : obs)
	{
		eraseObservation(oldP, k);
		auto kit = keyFrames_.find(k);
		if (kit == keyFrames_.end() || kit->second->bad) continue;
		// A keyframe that sees both keeps its observation of the new point (ORB-SLAM2's Replace).
		if (!newP.observations.count(k)) addObservation(newP, *kit->second, kp);
	}
	newP.visible += oldP.visible;
	newP.found += oldP.found;
	markBadLocked(oldP);
	oldP.replacedBy = newId;
	return true;
}

void CSparseMap::eraseKeyFrameLocked(CKeyFrame& kf)
{
	// ORB-SLAM2's KeyFrame::SetBadFlag: drop the observations, then re-hang the children in the
	// spanning tree, each under the candidate (the parent, or a child already re-hung) it shares
	// most points with; children that share none with any candidate go to the parent.
	for (std::size_t i = 0; i < kf.mapPoints.size(); i++)
	{
		const TPointId pid = kf.mapPoints[i];
		if (pid < 0) continue;
		auto it = points_.find(pid);
		if (it == points_.end()) continue;
		eraseObservation(it->second, kf.id);
		if (!it->second.bad && it->second.observations.empty()) markBadLocked(it->second);
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
			const CKeyFrame& ck = *keyFrames_.at(c);
			for (TKeyFrameId cand : candidates)
				if (const int w = ck.weight(cand); w > best)
				{
					best = w;
					bestChild = c;
					bestParent = cand;
				}
		}
		if (best == 0) break;
		CKeyFrame& ck = *keyFrames_.at(bestChild);
		ck.parent = bestParent;
		keyFrames_.at(bestParent)->children.insert(bestChild);
		candidates.insert(bestChild);
		children.erase(bestChild);
	}
	for (TKeyFrameId c : children)
	{
		keyFrames_.at(c)->parent = parent;
		keyFrames_.at(parent)->children.insert(c);
	}
	kf.children.clear();
	keyFrames_.at(parent)->children.erase(kf.id);
	kf.poseInParent = kf.pose - keyFrames_.at(parent)->pose;
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
	numGoodKeyFrames_--;
}

bool CSparseMap::eraseKeyFrame(TKeyFrameId id)
{
	WriteLock lk(mtx_);
	auto it = keyFrames_.find(id);
	if (it == keyFrames_.end() || it->second->bad || !it->second->parent) return false;	 // the root stays
	eraseKeyFrameLocked(*it->second);
	return true;
}

std::vector<TKeyFrameId> CSparseMap::cullRedundantKeyFrames(
	TKeyFrameId currentKf, double redundantRatio, std::size_t minOtherObservers, double maxDepth)
{
	WriteLock lk(mtx_);
	std::vector<TKeyFrameId> erased;
	const auto cit = keyFrames_.find(currentKf);
	if (cit == keyFrames_.end() || cit->second->bad) return erased;
	const std::vector<TKeyFrameId> local = cit->second->orderedConnections;
	for (TKeyFrameId id : local)
	{
		auto it = keyFrames_.find(id);
		if (it == keyFrames_.end()) continue;
		CKeyFrame& kf = *it->second;
		// A keyframe that closes a loop stays (ORB-SLAM2's SetNotErase): erased, its loop edge would
		// leave the essential graph, and a later pose graph would lose the loop without a word.
		if (kf.bad || !kf.parent || id == currentKf || !kf.loopEdges.empty()) continue;
		std::size_t numPoints = 0, redundant = 0;
		for (std::size_t i = 0; i < kf.mapPoints.size(); i++)
		{
			const TPointId pid = kf.mapPoints[i];
			if (pid < 0) continue;
			const auto pit = points_.find(pid);
			if (pit == points_.end() || pit->second.bad) continue;
			const float z = kf.features->depth[i];
			if (!(z > 0) || z > maxDepth) continue;	 // RGB-D: only close points count (ORB-SLAM2)
			numPoints++;
			const CMapPoint& p = pit->second;
			if (p.observations.size() <= minOtherObservers) continue;
			const int octave = kf.features->keypoints[i].octave;
			std::size_t others = 0;
			for (const auto& [k, kp] : p.observations)
			{
				if (k == id) continue;
				const CKeyFrame& o = *keyFrames_.at(k);
				if (o.features->keypoints[kp].octave <= octave + 1 && ++others >= minOtherObservers) break;
			}
			if (others >= minOtherObservers) redundant++;
		}
		if (numPoints > 0 && static_cast<double>(redundant) > redundantRatio * static_cast<double>(numPoints))
		{
			eraseKeyFrameLocked(kf);
			erased.push_back(id);
		}
	}
	return erased;
}

TBundleWindow CSparseMap::bundleWindow(TKeyFrameId id, std::size_t numCovisible, std::size_t maxFixed) const
{
	ReadLock lk(mtx_);
	TBundleWindow w;
	w.generation = generation_;
	const auto cit = keyFrames_.find(id);
	if (cit == keyFrames_.end() || cit->second->bad) return w;
	w.keyFrames = covisibleLocked(id, numCovisible, 1);
	w.keyFrames.insert(w.keyFrames.begin(), id);
	const std::set<TKeyFrameId> local(w.keyFrames.begin(), w.keyFrames.end());
	std::set<TPointId> pts;
	for (TKeyFrameId k : w.keyFrames)
		for (TPointId pid : keyFrames_.at(k)->mapPoints)
			if (pid >= 0)
				if (auto it = points_.find(pid); it != points_.end() && !it->second.bad) pts.insert(pid);
	std::map<TKeyFrameId, int> fixedCount;
	for (TPointId pid : pts)
		for (const auto& [k, kp] : points_.at(pid).observations)
			if (!local.count(k)) fixedCount[k]++;
	std::vector<std::pair<int, TKeyFrameId>> order;
	for (const auto& [k, n] : fixedCount) order.emplace_back(-n, k);
	std::sort(order.begin(), order.end());
	for (std::size_t i = 0; i < order.size() && w.fixedKeyFrames.size() < maxFixed; i++)
		w.fixedKeyFrames.push_back(order[i].second);
	// The first keyframe anchors the gauge (ORB-SLAM2 fixes the origin keyframe).
	const TKeyFrameId root = keyFrames_.begin()->first;
	if (local.count(root))
	{
		w.keyFrames.erase(std::find(w.keyFrames.begin(), w.keyFrames.end(), root));
		w.fixedKeyFrames.push_back(root);
	}
	std::set<TKeyFrameId> all(w.keyFrames.begin(), w.keyFrames.end());
	all.insert(w.fixedKeyFrames.begin(), w.fixedKeyFrames.end());
	for (TKeyFrameId k : all)
	{
		const CKeyFrame& kf = *keyFrames_.at(k);
		w.poses[k] = kf.pose;
		w.features[k] = kf.features;
		w.cameras[k] = kf.camera;
	}
	for (TPointId pid : pts)
	{
		const auto& p = points_.at(pid);
		std::map<TKeyFrameId, std::size_t> obs;
		for (const auto& [k, kp] : p.observations)
			if (all.count(k)) obs[k] = kp;
		w.points.push_back(pid);
		w.positions.push_back(p.position);
		w.observations.push_back(std::move(obs));
	}
	return w;
}

void CSparseMap::eraseOutliersLocked(const std::vector<std::pair<TPointId, TKeyFrameId>>& outliers)
{
	for (const auto& [pid, k] : outliers)
	{
		auto it = points_.find(pid);
		if (it == points_.end() || it->second.bad) continue;
		eraseObservation(it->second, k);
		if (it->second.observations.empty()) markBadLocked(it->second);
	}
	reorderDirty();
}

bool CSparseMap::applyBundle(
	const TBundleWindow& w, const std::map<TKeyFrameId, mrpt::poses::CPose3D>& poses,
	const std::vector<mrpt::math::TPoint3D>& positions, const std::vector<std::pair<TPointId, TKeyFrameId>>& outliers)
{
	WriteLock lk(mtx_);
	if (w.generation != generation_) return false;
	for (const auto& [k, p] : poses)
		if (auto it = keyFrames_.find(k); it != keyFrames_.end() && !it->second->bad) it->second->pose = p;
	for (std::size_t i = 0; i < w.points.size() && i < positions.size(); i++)
		if (auto it = points_.find(w.points[i]); it != points_.end() && !it->second.bad) it->second.position = positions[i];
	eraseOutliersLocked(outliers);
	return true;
}

std::uint64_t CSparseMap::generation() const
{
	ReadLock lk(mtx_);
	return generation_;
}

std::uint64_t CSparseMap::beginCorrection()
{
	WriteLock lk(mtx_);
	return ++generation_;
}

bool CSparseMap::addLoopEdge(TKeyFrameId a, TKeyFrameId b)
{
	WriteLock lk(mtx_);
	const auto ia = keyFrames_.find(a), ib = keyFrames_.find(b);
	if (ia == keyFrames_.end() || ib == keyFrames_.end() || a == b) return false;
	ia->second->loopEdges.insert(b);
	ib->second->loopEdges.insert(a);
	return true;
}

std::vector<std::pair<TKeyFrameId, TKeyFrameId>> CSparseMap::essentialGraph(int minWeight) const
{
	ReadLock lk(mtx_);
	std::set<std::pair<TKeyFrameId, TKeyFrameId>> edges;
	auto add = [&](TKeyFrameId a, TKeyFrameId b)
	{
		if (a == b) return;
		const auto ia = keyFrames_.find(a), ib = keyFrames_.find(b);
		if (ia == keyFrames_.end() || ib == keyFrames_.end() || ia->second->bad || ib->second->bad) return;
		edges.insert({std::min(a, b), std::max(a, b)});
	};
	for (const auto& [id, kf] : keyFrames_)
	{
		if (kf->bad) continue;
		if (kf->parent) add(id, *kf->parent);
		for (const auto& [other, w] : kf->connections)
			if (w >= minWeight) add(id, other);
		for (const auto other : kf->loopEdges) add(id, other);
	}
	return {edges.begin(), edges.end()};
}

void CSparseMap::correctLocked(
	const std::map<TKeyFrameId, mrpt::poses::CPose3D>& poses, bool propagate, const std::set<TPointId>& skip)
{
	// Each moved keyframe's correction D = T_new (T_old)^-1, applied to what moves with it.
	std::map<TKeyFrameId, mrpt::poses::CPose3D> delta;
	for (const auto& [id, p] : poses)
		if (auto it = keyFrames_.find(id); it != keyFrames_.end() && !it->second->bad) delta[id] = p + (-it->second->pose);
	if (propagate)
		for (const auto& [id, kf] : keyFrames_)
		{
			if (kf->bad || delta.count(id)) continue;
			std::optional<TKeyFrameId> a = kf->parent;
			for (std::size_t hops = 0; a && !delta.count(*a) && hops <= keyFrames_.size(); hops++) a = keyFrames_.at(*a)->parent;
			if (a && delta.count(*a)) delta[id] = delta.at(*a);
		}
	if (!propagate) correctedBy_.clear();
	for (auto& [pid, p] : points_)
	{
		if (p.bad || skip.count(pid)) continue;
		const mrpt::poses::CPose3D* D = nullptr;
		if (propagate)
		{
			// A point the group step moved follows the keyframe that moved it, not its creator:
			// moved once with the group keyframe and again with its creator's correction, it
			// landed where neither puts it.
			const auto cb = correctedBy_.find(pid);
			const TKeyFrameId anchor = cb != correctedBy_.end() ? cb->second : p.firstKeyFrame;
			if (keyFrames_.count(anchor))
				if (auto it = delta.find(goodAncestorLocked(anchor)); it != delta.end()) D = &it->second;
		}
		else
			for (const auto& [k, kp] : p.observations)
				if (auto it = delta.find(k); it != delta.end())
				{
					D = &it->second;
					correctedBy_[pid] = k;
					break;
				}
		if (!D) continue;
		mrpt::math::TPoint3D q;
		D->composePoint(p.position, q);
		p.position = q;
	}
	for (const auto& [id, D] : delta)
	{
		auto& kf = *keyFrames_.at(id);
		const auto given = poses.find(id);
		kf.pose = orthonormalised(given != poses.end() ? given->second : D + kf.pose);
	}
	if (propagate) correctedBy_.clear();
	generation_++;
}

void CSparseMap::correctKeyFrames(const std::map<TKeyFrameId, mrpt::poses::CPose3D>& poses)
{
	WriteLock lk(mtx_);
	correctLocked(poses, false);
}

void CSparseMap::applyCorrection(const std::map<TKeyFrameId, mrpt::poses::CPose3D>& poses)
{
	WriteLock lk(mtx_);
	correctLocked(poses, true);
}

TBundleWindow CSparseMap::globalBundleWindow() const
{
	ReadLock lk(mtx_);
	TBundleWindow w;
	w.generation = generation_;
	for (const auto& [id, kf] : keyFrames_)
	{
		if (kf->bad) continue;
		(id == keyFrames_.begin()->first ? w.fixedKeyFrames : w.keyFrames).push_back(id);
		w.poses[id] = kf->pose;
		w.features[id] = kf->features;
		w.cameras[id] = kf->camera;
	}
	for (const auto& [pid, p] : points_)
	{
		if (p.bad) continue;
		std::map<TKeyFrameId, std::size_t> obs;
		for (const auto& [k, kp] : p.observations)
			if (w.poses.count(k)) obs[k] = kp;
		if (obs.empty()) continue;
		w.points.push_back(pid);
		w.positions.push_back(p.position);
		w.observations.push_back(std::move(obs));
	}
	return w;
}

bool CSparseMap::applyGlobalBundle(
	const TBundleWindow& w, const std::map<TKeyFrameId, mrpt::poses::CPose3D>& poses,
	const std::vector<mrpt::math::TPoint3D>& positions, const std::vector<std::pair<TPointId, TKeyFrameId>>& outliers)
{
	WriteLock lk(mtx_);
	if (w.generation != generation_) return false;
	// Keyframes and points made since the copy follow their ancestors' correction (ORB-SLAM2's
	// RunGlobalBundleAdjustment), the window's points take their optimised positions.
	const std::set<TPointId> optimised(w.points.begin(), w.points.end());
	correctLocked(poses, true, optimised);
	for (std::size_t i = 0; i < w.points.size() && i < positions.size(); i++)
		if (auto it = points_.find(w.points[i]); it != points_.end() && !it->second.bad) it->second.position = positions[i];
	eraseOutliersLocked(outliers);
	return true;
}

std::vector<TKeyFramePose> CSparseMap::keyFramePoses() const
{
	ReadLock lk(mtx_);
	std::vector<TKeyFramePose> out;
	out.reserve(keyFrames_.size());
	for (const auto& [id, kf] : keyFrames_) out.push_back({id, kf->timestamp, poseLocked(id), kf->bad});
	return out;
}

std::vector<CMapPoint> CSparseMap::points() const
{
	ReadLock lk(mtx_);
	std::vector<CMapPoint> out;
	out.reserve(numGoodPoints_);
	for (const auto& [id, p] : points_)
		if (!p.bad) out.push_back(p);
	std::sort(out.begin(), out.end(), [](const CMapPoint& a, const CMapPoint& b) { return a.id < b.id; });
	return out;
}
void CSparseMap::serialize(std::ostream& out) const
{
	using namespace binio;
	ReadLock lk(mtx_);
	put<std::uint32_t>(out, kSerialVersion);
	put<std::uint64_t>(out, nextKeyFrame_);
	put<std::int64_t>(out, nextPoint_);
	put<std::uint64_t>(out, generation_);
	put<std::uint64_t>(out, keyFrames_.size());
	for (const auto& [id, kf] : keyFrames_) kf->serialize(out);
	// Good points only, by id (the table's order is not deterministic; a saved map should be).
	std::vector<TPointId> ids;
	for (const auto& [id, p] : points_)
		if (!p.bad) ids.push_back(id);
	std::sort(ids.begin(), ids.end());
	put<std::uint64_t>(out, ids.size());
	for (TPointId id : ids) points_.at(id).serialize(out);
}

void CSparseMap::deserialize(std::istream& in)
{
	using namespace binio;
	getVersion(in, "map", kSerialVersion);
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
		if (kf->id >= nextKf || !kfs.emplace(kf->id, kf).second) throw std::runtime_error("keyframe id out of place reading map");
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
			if (it == kfs.end() || it->second->bad || kp >= it->second->mapPoints.size() || it->second->mapPoints[kp] != id)
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
		if (!finite(kf->pose) || !finite(kf->poseInParent)) throw std::runtime_error("keyframe pose not finite reading map");
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
	WriteLock lk(mtx_);
	keyFrames_ = std::move(kfs);
	points_ = std::move(pts);
	recent_.clear();
	dead_.clear();
	dirty_.clear();
	numGoodKeyFrames_ = goodKfs;
	numGoodPoints_ = points_.size();
	nextKeyFrame_ = nextKf;
	nextPoint_ = nextPt;
	generation_ = gen;
}
void CSparseMap::swapContent(CSparseMap& other)
{
	if (&other == this) return;
	std::scoped_lock lk(mtx_, other.mtx_);
	std::swap(keyFrames_, other.keyFrames_);
	std::swap(points_, other.points_);
	std::swap(recent_, other.recent_);
	std::swap(dead_, other.dead_);
	std::swap(dirty_, other.dirty_);
	std::swap(numGoodKeyFrames_, other.numGoodKeyFrames_);
	std::swap(numGoodPoints_, other.numGoodPoints_);
	std::swap(nextKeyFrame_, other.nextKeyFrame_);
	std::swap(nextPoint_, other.nextPoint_);
	std::swap(generation_, other.generation_);
	std::swap(correctedBy_, other.correctedBy_);
}
}  // namespace mrpt_yesslam
