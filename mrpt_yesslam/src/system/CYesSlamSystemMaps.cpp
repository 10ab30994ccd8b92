// CYesSlamSystem's maps as files and frames: the dense map's build, the export (world) frame, a
// saved map loaded and saved, and checkpoints while the run goes.
#include <map>
#include <mutex>
#include <shared_mutex>
#include <sstream>

#include "mrpt_yesslam/mapio/MapFile.h"
#include "mrpt_yesslam/system/CYesSlamSystem.h"
#include "mrpt_yesslam/util/Error.h"

namespace mrpt_yesslam
{
TDenseMap CYesSlamSystem::buildDenseMap() const
{
	if (!dense_) throw std::logic_error("dense mapping is off ([DenseMapping] enabled = false)");
	const mrpt::poses::CPose3D worldFromMap = worldFrame().worldFromMap;
	return dense_->build([&](TKeyFrameId id) { return worldFromMap + map_.keyFramePose(id); });
}

TWorldFrame CYesSlamSystem::worldFrame() const
{
	std::lock_guard<std::mutex> lk(worldFrameMtx_);
	if (!worldFrame_) worldFrame_ = findWorldFrame();
	return *worldFrame_;
}

TWorldFrame CYesSlamSystem::currentWorldFrame() const
{
	{
		std::lock_guard<std::mutex> lk(worldFrameMtx_);
		if (worldFrame_) return *worldFrame_;
	}
	return findWorldFrame();
}

TWorldFrame CYesSlamSystem::findWorldFrame() const
{
	TWorldFrame f;
	if (opts_.system.worldFrame == "zup")
	{
		// The first keyframe's camera (the map's origin unless a correction moved it).
		mrpt::poses::CPose3D first;
		std::optional<TKeyFrameId> firstId;
		for (const auto& k : map_.keyFramePoses())
			if (!firstId || k.id < *firstId) firstId = k.id, first = k.pose;
		// The dense clouds see the floor far better than the sparse points (textured spots only).
		std::vector<mrpt::math::TPoint3D> pts;
		if (dense_ && dense_->numKeyFrames() > 0)
		{
			const std::size_t step = std::max<std::size_t>(1, dense_->numStoredPoints() / 200000);
			for (const auto& p : dense_->worldPoints([this](TKeyFrameId id) { return map_.keyFramePose(id); }, step))
				pts.emplace_back(p.x, p.y, p.z);
		}
		else
			for (const auto& p : map_.points()) pts.push_back(p.position);
		f = estimateZUpWorldFrame(pts, first);
	}
	return f;
}

void CYesSlamSystem::loadMap(const std::string& path)
{
	if (nextFrameId_ > 0) throw std::logic_error("CYesSlamSystem::loadMap after the first frame");
	std::unique_ptr<CSemanticOcTree> octree;
	const TMapFileInfo info = loadMapFile(path, map_, vocabulary_ ? vocabulary_->fingerprint() : 0, &octree);
	// The saved semantic OctoMap is where this run's dense map starts: the map stays up to date
	// from one run to the next instead of holding only what this run saw. A run without a dense
	// map (localisation only) keeps it as it is, so that saving the map again keeps it too.
	if (dense_ && octree) dense_->setPrior(*octree);
	if (!dense_) loadedOctree_ = std::move(octree);
	// The saved octree is in the frame the map was exported in: this run's exports stay in it.
	{
		std::lock_guard<std::mutex> lk(worldFrameMtx_);
		worldFrame_ = info.worldFrame;
	}
	// What the run uses (options() and config_used.ini say so), whatever [System] worldFrame asked.
	opts_.system.worldFrame = info.worldFrame.kind == TWorldFrame::EKind::ZUp ? "zup" : "optical";
	if (map_.numKeyFrames() == 0) throw InputError(path, "the map has no keyframes");
	if (loopClosing_)
		loopClosing_->setSessionStart(map_.keyFrameIds().back() +
									  1);  // the saved keyframes are all of an earlier session
	for (TKeyFrameId id : map_.keyFrameIds()) addWords(id);
}

void CYesSlamSystem::saveMap(const std::string& path, const CSemanticOcTree* octree) const
{
	saveMapFile(path, map_, vocabulary_ ? vocabulary_->fingerprint() : 0, octree ? octree : loadedOctree_.get(),
				worldFrame());
}

CYesSlamSystem::TFramedOctree CYesSlamSystem::checkpointOctree() const
{
	TFramedOctree out;
	out.frame = currentWorldFrame();
	if (!dense_) return out;
	// The keyframes' poses of one state (shared map-update lock: no loop correction half applied);
	// the build after, unlocked. A keyframe the dense stage got since is placed at its pose then.
	std::map<TKeyFrameId, mrpt::poses::CPose3D> poses;
	{
		std::shared_lock<CWriterFirstMutex> lk(mapUpdateMtx_);
		for (const auto& k : map_.keyFramePoses()) poses[k.id] = k.pose;
	}
	out.tree = dense_
				   ->build(
					   [&](TKeyFrameId id)
					   {
						   const auto it = poses.find(id);
						   return out.frame.worldFromMap + (it != poses.end() ? it->second : map_.keyFramePose(id));
					   })
				   .octree;
	return out;
}

bool CYesSlamSystem::checkpointMap(const std::string& path, const TFramedOctree* octree) const
{
	std::ostringstream bytes(std::ios::binary);
	{
		std::shared_lock<CWriterFirstMutex> lk(mapUpdateMtx_);  // no loop correction half applied
		if (map_.numKeyFrames() == 0) return false;
		map_.serialize(bytes);
	}
	const bool withTree = octree && octree->tree;
	saveSerializedMapFile(path, std::move(bytes).str(), vocabulary_ ? vocabulary_->fingerprint() : 0,
						  withTree ? octree->tree.get() : loadedOctree_.get(),
						  withTree ? octree->frame : currentWorldFrame(), true);
	return true;
}
}  // namespace mrpt_yesslam
