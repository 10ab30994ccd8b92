#pragma once
// A keyframe of the sparse map: the one owner of everything the map keeps of a tracked frame
// (measurements, pose, point associations, its place in the covisibility graph and the spanning
// tree). Only CSparseMap changes a keyframe, under the map's lock; tracking and the other stages
// read copies the map hands out, so none of them keeps a stale pose or association of its own.
#include <mrpt/img/TCamera.h>
#include <mrpt/poses/CPose3D.h>

#include <cstdint>
#include <iosfwd>
#include <map>
#include <memory>
#include <optional>
#include <set>
#include <vector>

#include "mrpt_yesslam/data/CMapPoint.h"
#include "mrpt_yesslam/data/TBow.h"
#include "mrpt_yesslam/data/TFrame.h"

namespace mrpt_yesslam
{
/** A keyframe. */
struct CKeyFrame
{
	TKeyFrameId id = 0;
	std::size_t frameId = 0;    //!< index of its frame in the input stream
	double timestamp = 0;       //!< seconds
	mrpt::img::TCamera camera;  //!< intrinsics; keypoints are already undistorted
	/** Keypoints (undistorted), descriptors, depth, dynamic flags: never changed after insertion,
	 * so copies of the keyframe and bundle-adjustment windows share them without a lock. */
	std::shared_ptr<const TFeatures> features;
	std::vector<cv::Vec3b> colors;  //!< BGR at each keypoint
	std::vector<TDetection> detections;
	mrpt::poses::CPose3D pose;        //!< T_w_c; written only by the map (insertion, optimisers)
	std::vector<TPointId> mapPoints;  //!< per keypoint, -1 = none
	/** Its words (place recognition), set by local mapping once computed; null before, or without
	 * a vocabulary. Shared read-only like the features. */
	std::shared_ptr<const TBow> bow;
	bool bad = false;  //!< erased (redundant): measurements dropped, pose kept relative to the parent

	/** Covisibility graph: keyframe -> number of map points both observe (> 0), kept up to date by the map. */
	std::map<TKeyFrameId, int> connections;
	/** The same keyframes by weight, heaviest first (ties: older first). */
	std::vector<TKeyFrameId> orderedConnections;
	/** Spanning tree (ORB-SLAM2's essential graph backbone): the best-connected older keyframe at insertion. */
	std::optional<TKeyFrameId> parent;
	std::set<TKeyFrameId> children;
	/** Keyframes it closed a loop with (kept in the essential graph of later corrections). */
	std::set<TKeyFrameId> loopEdges;
	/** Stages using it now (loop closing between detection and correction): culling leaves it
	 * (ORB-SLAM2's SetNotErase / SetErase). Not saved with the map. */
	int pinned = 0;
	/** Once bad: its pose relative to its parent (T_parent_this), so frames tracked from it still resolve. */
	mrpt::poses::CPose3D poseInParent;

	/** Number of keypoints. */
	std::size_t size() const { return features ? features->keypoints.size() : 0; }
	/** Static keypoint with depth in (0, maxDepth]. */
	bool usable(std::size_t i, double maxDepth) const { return features->usable(i, maxDepth); }
	/** The 3D point of keypoint i in the camera frame (needs depth). */
	cv::Point3d backProject(std::size_t i) const;
	/** Weight of the edge to `other` (0 = not covisible). */
	int weight(TKeyFrameId other) const
	{
		const auto it = connections.find(other);
		return it == connections.end() ? 0 : it->second;
	}

	/** Format version written by serialize(); read() refuses newer ones (2: loop edges). */
	static constexpr std::uint32_t kSerialVersion = 2;
	/** Writes the keyframe (measurements, pose, associations, graph) in a compact versioned binary form. */
	void serialize(std::ostream& out) const;
	/** Reads what serialize() wrote; throws std::runtime_error for a truncated stream or an unknown version. */
	static CKeyFrame deserialize(std::istream& in);
};
}  // namespace mrpt_yesslam
