#include "mrpt_yesslam/mapio/MapSummary.h"
#include "mrpt_yesslam/util/TextParsing.h"

#include <algorithm>
#include <cstdio>
#include <limits>
#include <map>

namespace mrpt_yesslam
{
TMapSummary summarizeMap(const CSparseMap& map, const std::vector<std::string>& classNames,
						 const mrpt::poses::CPose3D& worldFromMap)
{
	TMapSummary s;
	std::map<int, std::size_t> seen;
	const mrpt::poses::CPose3D* last = nullptr;
	const auto poses = map.keyFramePoses();
	for (const auto& k : poses)
	{
		if (k.bad)
		{
			s.erasedKeyFrames++;
			continue;
		}
		if (s.keyFrames++ == 0) s.firstTime = k.timestamp;
		s.lastTime = std::max(s.lastTime, k.timestamp);
		if (last) s.pathLength += (k.pose - *last).norm();
		last = &k.pose;
		const CKeyFrame kf = map.keyFrame(k.id);
		s.loopEdges += kf.loopEdges.size();
		std::vector<int> classes;
		for (const auto& d : kf.detections) classes.push_back(d.classId);
		std::sort(classes.begin(), classes.end());
		classes.erase(std::unique(classes.begin(), classes.end()), classes.end());
		for (int c : classes) seen[c]++;
	}
	s.loopEdges /= 2;  // stored on both keyframes
	const double inf = std::numeric_limits<double>::infinity();
	s.min = {inf, inf, inf};
	s.max = {-inf, -inf, -inf};
	for (const auto& p : map.points())
	{
		s.points++;
		const auto w = worldFromMap.composePoint(p.position);
		for (int a = 0; a < 3; a++)
		{
			s.min[a] = std::min(s.min[a], w[a]);
			s.max[a] = std::max(s.max[a], w[a]);
		}
	}
	if (!s.points) s.min = s.max = {0, 0, 0};
	for (const auto& [c, n] : seen)
		s.classes.emplace_back(
			c >= 0 && static_cast<std::size_t>(c) < classNames.size() ? classNames[c] : "class " + std::to_string(c),
			n);
	std::stable_sort(s.classes.begin(), s.classes.end(),
					 [](const auto& a, const auto& b) { return a.second > b.second; });
	return s;
}

std::string formatMapSummary(const TMapSummary& s)
{
	char buf[512];
	std::string out;
	std::snprintf(buf, sizeof(buf), "keyframes:    %zu (%zu erased ones kept for their poses)\n", s.keyFrames,
				  s.erasedKeyFrames);
	out += buf;
	std::snprintf(buf, sizeof(buf), "map points:   %zu\n", s.points);
	out += buf;
	std::snprintf(buf, sizeof(buf), "extent:       x %.2f..%.2f  y %.2f..%.2f  z %.2f..%.2f m (%.2f x %.2f x %.2f m)\n",
				  s.min.x, s.max.x, s.min.y, s.max.y, s.min.z, s.max.z, s.max.x - s.min.x, s.max.y - s.min.y,
				  s.max.z - s.min.z);
	out += buf;
	std::snprintf(buf, sizeof(buf),
				  "time span:    %.1f s of keyframes, %.2f m from keyframe to keyframe, %zu loop edges\n",
				  s.lastTime - s.firstTime, s.pathLength, s.loopEdges);
	out += buf;
	out += "labels:      ";
	if (s.classes.empty()) out += " none";
	for (std::size_t i = 0; i < s.classes.size(); i++)
		out += (i ? ", " : " ") + s.classes[i].first + " (" + countOf(s.classes[i].second, "keyframe") + ")";
	out += "\n";
	return out;
}

TDenseCloud mapPointCloud(const CSparseMap& map, const mrpt::poses::CPose3D& worldFromMap)
{
	TDenseCloud c;
	for (const auto& p : map.points())
	{
		const auto w = worldFromMap.composePoint(p.position);
		c.xyz.emplace_back(static_cast<float>(w.x), static_cast<float>(w.y), static_cast<float>(w.z));
		c.bgr.push_back(p.color);
		c.label.push_back(0);
		c.labelProb.push_back(0.f);
		c.observations.push_back(static_cast<std::uint32_t>(p.observations.size()));
	}
	return c;
}

std::unique_ptr<CSemanticOcTree> mapOccupancy(const CSparseMap& map, double resolution,
											  const mrpt::poses::CPose3D& worldFromMap)
{
	auto tree = std::make_unique<CSemanticOcTree>(resolution);
	// One hit (0.7) is occupied: the map's points are already the confirmed ones. A point that later
	// rays contradict falls to the seen floor (0.51): unknown, not occupied as at OctoMap's 0.5.
	tree->setOccupancyThres(0.6);
	for (const TKeyFrameId id : map.keyFrameIds())
	{
		const TLocalMapPoints pts = map.keyFramePoints(id);
		const auto pose = worldFromMap + map.keyFramePose(id);
		octomap::Pointcloud cloud;
		for (const auto& q : pts.positions)
		{
			const auto p = worldFromMap.composePoint(q);
			cloud.push_back(static_cast<float>(p.x), static_cast<float>(p.y), static_cast<float>(p.z));
		}
		// As the dense map's octree: rays clear space up to a voxel before each point.
		tree->insertScan(
			cloud,
			octomap::point3d(static_cast<float>(pose.x()), static_cast<float>(pose.y()), static_cast<float>(pose.z())),
			resolution);
	}
	tree->updateInnerOccupancy();
	return tree;
}
}  // namespace mrpt_yesslam
