// yesslam-map: what a saved map (.ysm, yesslam --save-map) holds, and the map as a scene, a point
// cloud or an occupancy octree.
#include <cstdio>
#include <filesystem>
#include <map>

#include "mrpt_yesslam/dense/DenseMapExport.h"
#include "mrpt_yesslam/detection/CObjectDetector.h"
#include "mrpt_yesslam/mapio/MapFile.h"
#include "mrpt_yesslam/mapio/MapSummary.h"
#include "mrpt_yesslam/io/SceneExport.h"
#include "mrpt_yesslam/system/SlamExport.h"
#include "mrpt_yesslam/util/CommandLine.h"
#include "mrpt_yesslam/util/Error.h"
#include "mrpt_yesslam/util/ShareDir.h"

using namespace mrpt_yesslam;

int main(int argc, char** argv)
{
	return runTool(
		"yesslam-map",
		[&]() -> int
		{
			std::string map, scene, ply, bt, ot;
			double resolution = 0.05;
			CommandLine cl("yesslam-map",
						   "yesslam-map --map MAP.ysm [--scene OUT.3Dscene] [--ply OUT.ply] [--bt OUT.bt [--resolution "
						   "M]] [--ot OUT.ot]",
						   "Prints what a map saved by `yesslam --save-map` holds: keyframes, map points, the extent "
						   "of the points,\n"
						   "the time span and path of the keyframes, loop edges, and the object classes its keyframes "
						   "saw. Exports\n"
						   "the map as an MRPT scene (points, keyframe frustums and path: SceneViewer3D, "
						   "yesslam-render), as a PLY\n"
						   "point cloud (colour; observations = keyframes seeing each point), and the semantic OctoMap "
						   "saved with it\n"
						   "(when the run built one) as .ot (occupancy, colour, label) or .bt (occupancy: octovis, "
						   "octomap_server); a map\n"
						   "saved without one gets a .bt of its points (each keyframe's points inserted from its "
						   "camera: the space in\n"
						   "front of them free). Files are written atomically. The map is only read (any vocabulary).",
						   {"yesslam-map --map office.ysm",
							"yesslam-map --map office.ysm --scene office.3Dscene --ply office.ply --bt office.bt"});
			cl.text("map", "MAP.ysm", "the saved map", &map, true);
			cl.text("scene", "FILE", "write the map as an MRPT .3Dscene", &scene);
			cl.text("ply", "FILE",
					"write the sparse map points as a binary PLY (colour, observations; no labels: the dense semantic "
					"cloud is yesslam's dense_cloud.ply)",
					&ply);
			cl.text("bt", "FILE",
					"write the occupancy OctoMap (.bt): the saved semantic octree's, else one of the map points", &bt);
			cl.text("ot", "FILE", "write the saved semantic OctoMap (.ot: occupancy, colour, label)", &ot);
			cl.number("resolution", "M",
					  "voxel size of a --bt made from the points, in metres (0.005..10, default 0.05)", &resolution);
			if (!cl.parse(argc, argv)) return 0;
			if (!(resolution >= 0.005 && resolution <= 10))
				throw InputError("", "--resolution must be between 0.005 and 10 m");
			CSparseMap m;
			// Any vocabulary: the fingerprint check is for runs that localise in the map.
			std::unique_ptr<CSemanticOcTree> octree;
			const TMapFileInfo info = loadMapFile(map, m, 0, &octree);
			std::vector<std::string> names;
			const std::string share = shareDir();
			std::error_code ec;
			if (!share.empty() && std::filesystem::exists(share + "/models/yolo-fastest-1.1/coco.names", ec))
				names = readClassNames(share + "/models/yolo-fastest-1.1/coco.names");
			std::printf("map:          %s (format %u, %.1f MB, vocabulary %016llx)\n", map.c_str(), info.version,
						info.bytes / 1e6, static_cast<unsigned long long>(info.vocabularyFingerprint));
			std::fputs(formatMapSummary(summarizeMap(m, names, info.worldFrame.worldFromMap)).c_str(), stdout);
			const std::string frame = info.worldFrame.describe();
			std::printf("exports in:   %s\n", frame.substr(0, frame.find('\n')).c_str());
			if (octree)
			{
				std::map<std::string, std::size_t> byLabel;
				std::size_t occupied = 0;
				for (auto it = octree->begin_leafs(), end = octree->end_leafs(); it != end; ++it)
					if (octree->isNodeOccupied(*it))
					{
						occupied++;
						byLabel[labelName(it->label, names)]++;
					}
				std::string labels;
				for (const auto& [name, n] : byLabel)
					labels += (labels.empty() ? "" : ", ") + name + " " + std::to_string(n);
				std::printf("octree:       %zu occupied voxels at %.3f m (%s)\n", occupied, octree->getResolution(),
							labels.c_str());
			}
			else
				std::printf("octree:       none (the run that saved the map had no dense map)\n");
			if (!ot.empty())
			{
				if (!octree) throw InputError(map, "has no semantic octree to write to " + ot);
				writeSemanticOcTree(ot, *octree);
				std::printf("ot:           %s\n", ot.c_str());
			}
			if (!scene.empty())
			{
				TTrajectory path;
				for (const auto& k : m.keyFramePoses())
					if (!k.bad)
						path.push_back(TStampedPose::fromPose(k.timestamp, info.worldFrame.worldFromMap + k.pose));
				saveSceneAtomically(*buildMapScene(m, path, info.worldFrame.worldFromMap), scene);
				std::printf("scene:        %s\n", scene.c_str());
			}
			if (!ply.empty())
			{
				writeDenseCloudPly(
					ply, mapPointCloud(m, info.worldFrame.worldFromMap), names,
					"sparse map points, without labels (label 0; the dense semantic map is yesslam's dense_cloud.ply)",
					info.worldFrame.describe());
				std::printf("ply:          %s\n", ply.c_str());
			}
			if (!bt.empty())
			{
				const auto fromPoints = octree ? nullptr : mapOccupancy(m, resolution, info.worldFrame.worldFromMap);
				const CSemanticOcTree& tree = octree ? *octree : *fromPoints;
				writeOccupancyBt(bt, tree);
				std::printf("bt:           %s (%zu leaves at %.3f m, %s)\n", bt.c_str(), tree.getNumLeafNodes(),
							tree.getResolution(), octree ? "the saved semantic octree" : "from the map points");
			}
			return 0;
		});
}
