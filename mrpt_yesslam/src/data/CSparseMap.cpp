#include "mrpt_yesslam/data/CSparseMap.h"

#include <algorithm>
#include <mutex>
#include <set>

namespace mrpt_yesslam
{
using ReadLock = std::shared_lock<std::shared_mutex>;
using WriteLock = std::unique_lock<std::shared_mutex>;

std::size_t CSparseMap::addKeyFrame(const std::shared_ptr<const TFrame>& frame, double maxDepth, std::size_t* newPoints)
{
	WriteLock lk(mtx_);
	CKeyFrame kf;
	kf.id = keyFrames_.size();
	kf.frame = frame;
	kf.pose = frame->pose;
	kf.mapPoints.assign(frame->size(), -1);
	std::size_t created = 0;
	for (std::size_t i = 0; i < frame->size(); i++)
	{
		const TPointId pid = i < frame->mapPoints.size() ? frame->mapPoints[i] : -1;
		if (pid >= 0)
		{
			auto it = points_.find(pid);
			if (it != points_.end() && !it->second.bad && !it->second.observations.count(kf.id))
			{
				it->second.observations[kf.id] = i;
				kf.mapPoints[i] = pid;
				continue;
			}
		}
		if (!frame->usable(i, maxDepth)) continue;
		const cv::Point3d pc = frame->backProject(i);
		CMapPoint p;
		p.id = nextPoint_++;
		double gx, gy, gz;
		frame->pose.composePoint(pc.x, pc.y, pc.z, gx, gy, gz);
		p.position = {gx, gy, gz};
		p.descriptor = frame->features.descriptors.row(static_cast<int>(i)).clone();
		p.color = i < frame->colors.size() ? frame->colors[i] : cv::Vec3b(128, 128, 128);
		p.observations[kf.id] = i;
		p.firstKeyFrame = kf.id;
		kf.mapPoints[i] = p.id;
		points_.emplace(p.id, std::move(p));
		created++;
	}
	if (newPoints) *newPoints = created;
	keyFrames_.push_back(std::move(kf));
	return keyFrames_.back().id;
}

std::size_t CSparseMap::numKeyFrames() const
{
	ReadLock lk(mtx_);
	return keyFrames_.size();
}

std::size_t CSparseMap::numPoints() const
{
	ReadLock lk(mtx_);
	return static_cast<std::size_t>(
		std::count_if(points_.begin(), points_.end(), [](const auto& p) { return !p.second.bad; }));
}

mrpt::poses::CPose3D CSparseMap::keyFramePose(std::size_t id) const
{
	ReadLock lk(mtx_);
	return keyFrames_.at(id).pose;
}

CKeyFrame CSparseMap::keyFrame(std::size_t id) const
{
	ReadLock lk(mtx_);
	return keyFrames_.at(id);
}

namespace
{
std::vector<std::size_t> covisibleLocked(
	const std::vector<CKeyFrame>& kfs, const std::map<TPointId, CMapPoint>& pts, std::size_t id, std::size_t max)
{
	std::map<std::size_t, int> shared;
	for (TPointId pid : kfs.at(id).mapPoints)
	{
		if (pid < 0) continue;
		const auto it = pts.find(pid);
		if (it == pts.end() || it->second.bad) continue;
		for (const auto& [k, kp] : it->second.observations)
			if (k != id) shared[k]++;
	}
	std::vector<std::pair<int, std::size_t>> order;
	for (const auto& [k, n] : shared) order.emplace_back(-n, k);
	std::sort(order.begin(), order.end());
	std::vector<std::size_t> out;
	for (std::size_t i = 0; i < order.size() && out.size() < max; i++) out.push_back(order[i].second);
	return out;
}

void appendPoint(TLocalMapPoints& out, const CMapPoint& p)
{
	out.ids.push_back(p.id);
	out.positions.push_back(p.position);
	out.descriptors.push_back(p.descriptor);
}
}  // namespace

std::vector<std::size_t> CSparseMap::covisible(std::size_t id, std::size_t max) const
{
	ReadLock lk(mtx_);
	return covisibleLocked(keyFrames_, points_, id, max);
}

TLocalMapPoints CSparseMap::localPoints(std::size_t id, std::size_t numCovisible) const
{
	ReadLock lk(mtx_);
	TLocalMapPoints out;
	if (id >= keyFrames_.size()) return out;
	auto kfs = covisibleLocked(keyFrames_, points_, id, numCovisible);
	kfs.insert(kfs.begin(), id);
	std::set<TPointId> seen;
	for (std::size_t k : kfs)
		for (TPointId pid : keyFrames_[k].mapPoints)
		{
			if (pid < 0 || !seen.insert(pid).second) continue;
			const auto it = points_.find(pid);
			if (it != points_.end() && !it->second.bad) appendPoint(out, it->second);
		}
	return out;
}

TLocalMapPoints CSparseMap::keyFramePoints(std::size_t id, std::vector<std::size_t>* keypoints) const
{
	ReadLock lk(mtx_);
	TLocalMapPoints out;
	if (keypoints) keypoints->clear();
	if (id >= keyFrames_.size()) return out;
	const auto& kf = keyFrames_[id];
	for (std::size_t i = 0; i < kf.mapPoints.size(); i++)
	{
		const auto it = points_.find(kf.mapPoints[i]);
		if (it == points_.end() || it->second.bad) continue;
		appendPoint(out, it->second);
		if (keypoints) keypoints->push_back(i);
	}
	return out;
}

TLocalMapPoints CSparseMap::pointsById(const std::vector<TPointId>& ids) const
{
	ReadLock lk(mtx_);
	TLocalMapPoints out;
	for (TPointId id : ids)
		if (auto it = points_.find(id); it != points_.end() && !it->second.bad) appendPoint(out, it->second);
	return out;
}

void CSparseMap::countTracking(const std::vector<TPointId>& visible, const std::vector<TPointId>& found)
{
	WriteLock lk(mtx_);
	for (TPointId id : visible)
		if (auto it = points_.find(id); it != points_.end()) it->second.visible++;
	for (TPointId id : found)
		if (auto it = points_.find(id); it != points_.end()) it->second.found++;
}

void CSparseMap::eraseObservation(CMapPoint& p, std::size_t kf)
{
	const auto it = p.observations.find(kf);
	if (it == p.observations.end()) return;
	auto& slot = keyFrames_[kf].mapPoints[it->second];
	if (slot == p.id) slot = -1;
	p.observations.erase(it);
}

std::size_t CSparseMap::cullRecentPoints(std::size_t currentKf, double minFoundRatio, std::size_t minObservations)
{
	WriteLock lk(mtx_);
	std::size_t culled = 0;
	for (auto& [id, p] : points_)
	{
		if (p.bad) continue;
		// Only young points are judged (ORB-SLAM2 checks them for three keyframes after creation).
		if (p.firstKeyFrame + 3 < currentKf) continue;
		const double ratio = static_cast<double>(p.found) / std::max(1, p.visible);
		const bool tooRare = ratio < minFoundRatio;
		const bool tooFewViews = currentKf >= p.firstKeyFrame + 2 && p.observations.size() < minObservations;
		if (!tooRare && !tooFewViews) continue;
		p.bad = true;
		const auto obs = p.observations;
		for (const auto& [k, kp] : obs) eraseObservation(p, k);
		culled++;
	}
	return culled;
}

TBundleWindow CSparseMap::bundleWindow(std::size_t id, std::size_t numCovisible, std::size_t maxFixed) const
{
	ReadLock lk(mtx_);
	TBundleWindow w;
	if (id >= keyFrames_.size()) return w;
	w.keyFrames = covisibleLocked(keyFrames_, points_, id, numCovisible);
	w.keyFrames.insert(w.keyFrames.begin(), id);
	// Keyframe 0 anchors the gauge (ORB-SLAM2 fixes the origin keyframe).
	const std::set<std::size_t> local(w.keyFrames.begin(), w.keyFrames.end());
	std::set<TPointId> pts;
	for (std::size_t k : w.keyFrames)
		for (TPointId pid : keyFrames_[k].mapPoints)
			if (pid >= 0)
				if (auto it = points_.find(pid); it != points_.end() && !it->second.bad) pts.insert(pid);
	std::map<std::size_t, int> fixedCount;
	for (TPointId pid : pts)
		for (const auto& [k, kp] : points_.at(pid).observations)
			if (!local.count(k)) fixedCount[k]++;
	std::vector<std::pair<int, std::size_t>> order;
	for (const auto& [k, n] : fixedCount) order.emplace_back(-n, k);
	std::sort(order.begin(), order.end());
	for (std::size_t i = 0; i < order.size() && w.fixedKeyFrames.size() < maxFixed; i++)
		w.fixedKeyFrames.push_back(order[i].second);
	if (local.count(0))
	{
		w.keyFrames.erase(std::find(w.keyFrames.begin(), w.keyFrames.end(), std::size_t(0)));
		w.fixedKeyFrames.push_back(0);
	}
	std::set<std::size_t> all(w.keyFrames.begin(), w.keyFrames.end());
	all.insert(w.fixedKeyFrames.begin(), w.fixedKeyFrames.end());
	for (std::size_t k : all)
	{
		w.poses[k] = keyFrames_[k].pose;
		w.frames[k] = keyFrames_[k].frame;
	}
	for (TPointId pid : pts)
	{
		const auto& p = points_.at(pid);
		std::map<std::size_t, std::size_t> obs;
		for (const auto& [k, kp] : p.observations)
			if (all.count(k)) obs[k] = kp;
		w.points.push_back(pid);
		w.positions.push_back(p.position);
		w.observations.push_back(std::move(obs));
	}
	return w;
}

void CSparseMap::applyBundle(
	const std::map<std::size_t, mrpt::poses::CPose3D>& poses, const std::vector<TPointId>& points,
	const std::vector<mrpt::math::TPoint3D>& positions, const std::vector<std::pair<TPointId, std::size_t>>& outliers)
{
	WriteLock lk(mtx_);
	for (const auto& [k, p] : poses)
		if (k < keyFrames_.size()) keyFrames_[k].pose = p;
	for (std::size_t i = 0; i < points.size() && i < positions.size(); i++)
		if (auto it = points_.find(points[i]); it != points_.end()) it->second.position = positions[i];
	for (const auto& [pid, k] : outliers)
	{
		auto it = points_.find(pid);
		if (it == points_.end() || k >= keyFrames_.size()) continue;
		eraseObservation(it->second, k);
		if (it->second.observations.empty()) it->second.bad = true;
	}
}

std::vector<mrpt::poses::CPose3D> CSparseMap::keyFramePoses() const
{
	ReadLock lk(mtx_);
	std::vector<mrpt::poses::CPose3D> out;
	for (const auto& k : keyFrames_) out.push_back(k.pose);
	return out;
}

std::vector<double> CSparseMap::keyFrameTimes() const
{
	ReadLock lk(mtx_);
	std::vector<double> out;
	for (const auto& k : keyFrames_) out.push_back(k.frame->timestamp);
	return out;
}

std::vector<CMapPoint> CSparseMap::points() const
{
	ReadLock lk(mtx_);
	std::vector<CMapPoint> out;
	for (const auto& [id, p] : points_)
		if (!p.bad) out.push_back(p);
	return out;
}
}  // namespace mrpt_yesslam
