#include "mrpt_yesslam/keyframes/CRecentFrames.h"

#include <algorithm>
#include <map>

#include "mrpt_yesslam/keyframes/CSemanticKeyFrameSelector.h"

namespace mrpt_yesslam
{
void CRecentFrames::push(std::shared_ptr<const TFrame> frame, const TAnchor& anchor)
{
	frames_.push_back({std::move(frame), anchor});
	while (frames_.size() > capacity_) frames_.pop_front();
}

std::shared_ptr<const TFrame> CRecentFrames::tracked(std::size_t frameId, const CSparseMap& map) const
{
	const auto it =
		std::find_if(frames_.begin(), frames_.end(), [&](const TEntry& e) { return e.frame->id == frameId; });
	if (it == frames_.end() || !it->frame->tracked) return nullptr;
	// Placed where the map is now (ORB-SLAM2 inserts at once and has no such window).
	const mrpt::poses::CPose3D now = it->anchor.poseIn(map);
	if (now == it->frame->pose) return it->frame;
	auto moved = std::make_shared<TFrame>(*it->frame);
	moved->pose = now;
	return moved;
}

double motionToKeyFrame(const TFrame& f, const CKeyFrame& kf)
{
	std::map<TPointId, std::size_t> refKp;
	for (std::size_t i = 0; i < kf.mapPoints.size(); i++)
		if (kf.mapPoints[i] >= 0) refKp[kf.mapPoints[i]] = i;
	std::vector<Eigen::Vector3d> cur, prev;
	for (std::size_t i = 0; i < f.size(); i++)
	{
		if (f.mapPoints[i] < 0 || f.features.depth[i] <= 0) continue;
		const auto it = refKp.find(f.mapPoints[i]);
		if (it == refKp.end() || kf.features->depth[it->second] <= 0) continue;
		const cv::Point3d a = f.backProject(i), b = kf.backProject(it->second);
		cur.emplace_back(a.x, a.y, a.z);
		prev.emplace_back(b.x, b.y, b.z);
	}
	Eigen::Matrix3d R;
	Eigen::Vector3d t;
	if (cur.size() >= 10 && rigidMotionFromPoints(cur, prev, R, t)) return motionAmplitude(R, t);
	const mrpt::poses::CPose3D rel = f.pose - kf.pose;
	const auto Rm = rel.getRotationMatrix();
	for (int i = 0; i < 3; i++)
		for (int j = 0; j < 3; j++) R(i, j) = Rm(i, j);
	return motionAmplitude(R, Eigen::Vector3d(rel.x(), rel.y(), rel.z()));
}
}  // namespace mrpt_yesslam
