#include "mrpt_yesslam/data/CSparseMap.h"

#include <algorithm>
#include <mutex>
#include <stdexcept>

#include "MapCorrection.h"
#include "MapCulling.h"
#include "MapSerialization.h"
#include "MapWindows.h"
#include "SparseMapStore.h"

// The thread-safe face of the map: each call takes the one lock and hands the work to the store
// (storage and bookkeeping, SparseMapStore) or to the rules beside it (MapCulling, MapWindows,
// MapCorrection, MapSerialization).
namespace mrpt_yesslam
{
using ReadLock = std::shared_lock<std::shared_mutex>;
using WriteLock = std::unique_lock<std::shared_mutex>;

CSparseMap::CSparseMap() : s_(std::make_unique<TSparseMapStore>()) {}
CSparseMap::~CSparseMap() = default;

TKeyFrameId CSparseMap::addKeyFrame(const std::shared_ptr<const TFrame>& frame, double maxDepth, std::size_t* newPoints)
{
	WriteLock lk(mtx_);
	return s_->addKeyFrame(*frame, maxDepth, newPoints);
}

CSparseMap::TPin CSparseMap::addPinnedKeyFrame(const std::shared_ptr<const TFrame>& frame, double maxDepth)
{
	WriteLock lk(mtx_);
	const TKeyFrameId id = s_->addKeyFrame(*frame, maxDepth, nullptr);
	s_->keyFrames.at(id)->pinned++;
	return TPin(this, id);
}

bool CSparseMap::setKeyFrameBow(TKeyFrameId id, std::shared_ptr<const TBow> bow)
{
	WriteLock lk(mtx_);
	const auto it = s_->keyFrames.find(id);
	if (it == s_->keyFrames.end() || it->second->bad) return false;
	it->second->bow = std::move(bow);
	return true;
}

std::size_t CSparseMap::numKeyFrames() const
{
	ReadLock lk(mtx_);
	return s_->numGoodKeyFrames;
}

std::vector<TKeyFrameId> CSparseMap::keyFrameIds() const
{
	ReadLock lk(mtx_);
	std::vector<TKeyFrameId> out;
	for (const auto& [id, kf] : s_->keyFrames)
		if (!kf->bad) out.push_back(id);
	return out;
}

bool CSparseMap::hasKeyFrame(TKeyFrameId id) const
{
	ReadLock lk(mtx_);
	return s_->keyFrames.count(id) != 0;
}

bool CSparseMap::isBad(TKeyFrameId id) const
{
	ReadLock lk(mtx_);
	return s_->keyFrames.at(id)->bad;
}

bool CSparseMap::pinKeyFrame(TKeyFrameId id)
{
	WriteLock lk(mtx_);
	const auto it = s_->keyFrames.find(id);
	if (it == s_->keyFrames.end() || it->second->bad) return false;
	it->second->pinned++;
	return true;
}

void CSparseMap::unpinKeyFrame(TKeyFrameId id)
{
	WriteLock lk(mtx_);
	const auto it = s_->keyFrames.find(id);
	if (it != s_->keyFrames.end() && it->second->pinned > 0) it->second->pinned--;
}

CSparseMap::TPin& CSparseMap::TPin::operator=(TPin&& o) noexcept
{
	if (this != &o)
	{
		if (map_) map_->unpinKeyFrame(id_);
		map_ = o.map_;
		id_ = o.id_;
		o.map_ = nullptr;
	}
	return *this;
}

CSparseMap::TPin::~TPin()
{
	if (map_) map_->unpinKeyFrame(id_);
}

CSparseMap::TPin CSparseMap::pinned(TKeyFrameId id)
{
	return pinKeyFrame(id) ? TPin(this, id) : TPin();
}

TKeyFrameId CSparseMap::goodAncestor(TKeyFrameId id) const
{
	ReadLock lk(mtx_);
	return s_->goodAncestor(id);
}

std::size_t CSparseMap::numPoints() const
{
	ReadLock lk(mtx_);
	return s_->numGoodPoints;
}

mrpt::poses::CPose3D CSparseMap::keyFramePose(TKeyFrameId id) const
{
	ReadLock lk(mtx_);
	return s_->pose(id);
}

CKeyFrame CSparseMap::keyFrame(TKeyFrameId id) const
{
	ReadLock lk(mtx_);
	return *s_->keyFrames.at(id);
}

CMapPoint CSparseMap::point(TPointId id) const
{
	ReadLock lk(mtx_);
	if (const auto it = s_->points.find(id); it != s_->points.end()) return it->second;
	if (id < 0 || id >= s_->nextPoint) throw std::out_of_range("CSparseMap: no map point " + std::to_string(id));
	CMapPoint forgotten;  // erased long enough ago to be forgotten: all that is left is that it is bad
	forgotten.id = id;
	forgotten.bad = true;
	return forgotten;
}

std::size_t CSparseMap::numStoredPoints() const
{
	ReadLock lk(mtx_);
	return s_->points.size();
}

std::vector<TKeyFrameId> CSparseMap::covisible(TKeyFrameId id, std::size_t max, int minWeight) const
{
	ReadLock lk(mtx_);
	return s_->covisible(id, max, minWeight);
}

TLocalMapPoints CSparseMap::pointsOfKeyFrames(const std::vector<TKeyFrameId>& ids) const
{
	ReadLock lk(mtx_);
	return s_->pointsOfKeyFrames(ids);
}

TLocalMapPoints CSparseMap::pointsOfKeyFrames(const std::vector<TKeyFrameId>& ids, TKeyFrameId posed,
											  mrpt::poses::CPose3D& pose) const
{
	ReadLock lk(mtx_);
	pose = s_->pose(posed);
	return s_->pointsOfKeyFrames(ids);
}

std::vector<TKeyFrameId> CSparseMap::localKeyFrames(const std::vector<TPointId>& seeds, TKeyFrameId fallback,
													std::size_t maxKeyFrames, std::size_t neighbours) const
{
	ReadLock lk(mtx_);
	return sparse_map::localKeyFrames(*s_, seeds, fallback, maxKeyFrames, neighbours);
}

TLocalMapPoints CSparseMap::keyFramePoints(TKeyFrameId id, std::vector<std::size_t>* keypoints) const
{
	ReadLock lk(mtx_);
	TLocalMapPoints out;
	if (keypoints) keypoints->clear();
	const auto it = s_->keyFrames.find(id);
	if (it == s_->keyFrames.end()) return out;
	const auto& kf = *it->second;
	for (std::size_t i = 0; i < kf.mapPoints.size(); i++)
	{
		if (kf.mapPoints[i] < 0) continue;
		const auto pit = s_->points.find(kf.mapPoints[i]);
		if (pit == s_->points.end() || pit->second.bad) continue;
		s_->appendPoint(out, pit->second);
		if (keypoints) keypoints->push_back(i);
	}
	return out;
}
std::size_t CSparseMap::numKeyFramePoints(TKeyFrameId id, std::size_t minObservations) const
{
	ReadLock lk(mtx_);
	const auto it = s_->keyFrames.find(id);
	if (it == s_->keyFrames.end()) return 0;
	std::size_t n = 0;
	for (TPointId pid : it->second->mapPoints)
		if (pid >= 0)
			if (auto pit = s_->points.find(pid);
				pit != s_->points.end() && !pit->second.bad && pit->second.observations.size() >= minObservations)
				n++;
	return n;
}
TLocalMapPoints CSparseMap::pointsById(const std::vector<TPointId>& ids) const
{
	ReadLock lk(mtx_);
	TLocalMapPoints out;
	for (TPointId id : ids)
		if (const CMapPoint* p = s_->goodPoint(id)) s_->appendPoint(out, *p);
	return out;
}

std::size_t CSparseMap::countTracking(const std::vector<TPointId>& visible, const std::vector<TPointId>& found,
									  const std::vector<TPointId>& seenThrough, int seeThroughFrames)
{
	WriteLock lk(mtx_);
	return sparse_map::countTracking(*s_, visible, found, seenThrough, seeThroughFrames);
}

std::size_t CSparseMap::cullRecentPoints(TKeyFrameId currentKf, double minFoundRatio, std::size_t minObservations)
{
	WriteLock lk(mtx_);
	return sparse_map::cullRecentPoints(*s_, currentKf, minFoundRatio, minObservations);
}

std::size_t CSparseMap::numRecentPoints() const
{
	ReadLock lk(mtx_);
	return s_->recent.size();
}

std::vector<TKeyFrameId> CSparseMap::cullRedundantKeyFrames(TKeyFrameId currentKf, double redundantRatio,
															std::size_t minOtherObservers, double maxDepth)
{
	WriteLock lk(mtx_);
	return sparse_map::cullRedundantKeyFrames(*s_, currentKf, redundantRatio, minOtherObservers, maxDepth);
}

bool CSparseMap::eraseKeyFrame(TKeyFrameId id)
{
	WriteLock lk(mtx_);
	auto it = s_->keyFrames.find(id);
	if (it == s_->keyFrames.end() || it->second->bad || !it->second->parent) return false;  // the root stays
	s_->eraseKeyFrame(*it->second);
	return true;
}

bool CSparseMap::erasePoint(TPointId id)
{
	WriteLock lk(mtx_);
	auto it = s_->points.find(id);
	if (it == s_->points.end() || it->second.bad) return false;
	s_->dropPoint(it->second);
	s_->reorderDirty();
	return true;
}

bool CSparseMap::replacePoint(TPointId oldId, TPointId newId)
{
	WriteLock lk(mtx_);
	const bool ok = s_->replacePoint(oldId, newId);
	s_->reorderDirty();
	return ok;
}

std::size_t CSparseMap::fuse(const std::vector<TFuseCandidate>& candidates)
{
	WriteLock lk(mtx_);
	return s_->fuse(candidates);
}

TBundleWindow CSparseMap::bundleWindow(TKeyFrameId id, std::size_t numCovisible, std::size_t maxFixed) const
{
	ReadLock lk(mtx_);
	return sparse_map::bundleWindow(*s_, id, numCovisible, maxFixed);
}

bool CSparseMap::applyBundle(const TBundleWindow& w, const std::map<TKeyFrameId, mrpt::poses::CPose3D>& poses,
							 const std::vector<mrpt::math::TPoint3D>& positions,
							 const std::vector<std::pair<TPointId, TKeyFrameId>>& outliers)
{
	WriteLock lk(mtx_);
	return sparse_map::applyBundle(*s_, w, poses, positions, outliers);
}

std::uint64_t CSparseMap::generation() const
{
	ReadLock lk(mtx_);
	return s_->generation;
}

bool CSparseMap::addLoopEdge(TKeyFrameId a, TKeyFrameId b)
{
	WriteLock lk(mtx_);
	return sparse_map::addLoopEdge(*s_, a, b);
}

std::vector<std::pair<TKeyFrameId, TKeyFrameId>> CSparseMap::essentialGraph(int minWeight) const
{
	ReadLock lk(mtx_);
	return sparse_map::essentialGraph(*s_, minWeight);
}

void CSparseMap::correctKeyFrames(const std::map<TKeyFrameId, mrpt::poses::CPose3D>& poses)
{
	WriteLock lk(mtx_);
	sparse_map::correct(*s_, poses, false);
}

void CSparseMap::applyCorrection(const std::map<TKeyFrameId, mrpt::poses::CPose3D>& poses)
{
	WriteLock lk(mtx_);
	sparse_map::correct(*s_, poses, true);
}

TBundleWindow CSparseMap::globalBundleWindow() const
{
	ReadLock lk(mtx_);
	return sparse_map::globalBundleWindow(*s_);
}

bool CSparseMap::applyGlobalBundle(const TBundleWindow& w, const std::map<TKeyFrameId, mrpt::poses::CPose3D>& poses,
								   const std::vector<mrpt::math::TPoint3D>& positions,
								   const std::vector<std::pair<TPointId, TKeyFrameId>>& outliers)
{
	WriteLock lk(mtx_);
	return sparse_map::applyGlobalBundle(*s_, w, poses, positions, outliers);
}

std::vector<TKeyFramePose> CSparseMap::keyFramePoses() const
{
	ReadLock lk(mtx_);
	std::vector<TKeyFramePose> out;
	out.reserve(s_->keyFrames.size());
	for (const auto& [id, kf] : s_->keyFrames) out.push_back({id, kf->timestamp, s_->pose(id), kf->bad});
	return out;
}
std::vector<CMapPoint> CSparseMap::points() const
{
	ReadLock lk(mtx_);
	std::vector<CMapPoint> out;
	out.reserve(s_->numGoodPoints);
	for (const auto& [id, p] : s_->points)
		if (!p.bad) out.push_back(p);
	std::sort(out.begin(), out.end(), [](const CMapPoint& a, const CMapPoint& b) { return a.id < b.id; });
	return out;
}

void CSparseMap::serialize(std::ostream& out) const
{
	ReadLock lk(mtx_);
	sparse_map::serialize(*s_, out);
}

void CSparseMap::deserialize(std::istream& in)
{
	// Read and checked in full before the lock is taken: a bad file leaves the map as it was.
	auto fresh = sparse_map::deserialize(in);
	WriteLock lk(mtx_);
	s_.swap(fresh);
}

void CSparseMap::swapContent(CSparseMap& other)
{
	if (&other == this) return;
	std::scoped_lock lk(mtx_, other.mtx_);
	s_.swap(other.s_);
}
}  // namespace mrpt_yesslam
