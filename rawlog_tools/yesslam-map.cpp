// yesslam-map: what a saved map (.ysm, yesslam --save-map) holds, and the map as a scene, a point
// cloud or an occupancy octree.
#include <cstdio>
#include <filesystem>

#include "mrpt_yesslam/dense/DenseMapExport.h"
#include "mrpt_yesslam/detection/CObjectDetector.h"
#include "mrpt_yesslam/io/MapFile.h"
#include "mrpt_yesslam/io/MapSummary.h"
#include "mrpt_yesslam/io/SceneExport.h"
#include "mrpt_yesslam/io/SlamExport.h"
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
			std::string map, scene, ply, bt;
			double resolution = 0.05;
			CommandLine cl(
				"yesslam-map", "yesslam-map --map MAP.ysm [--scene OUT.3Dscene] [--ply OUT.ply] [--bt OUT.bt [--resolution M]]",
				"Prints what a map saved by `yesslam --save-map` holds: keyframes, map points, the extent of the points,\n"
				"the time span and path of the keyframes, loop edges, and the object classes its keyframes saw. Exports\n"
				"the map as an MRPT scene (points, keyframe frustums and path: SceneViewer3D, yesslam-render), as a PLY\n"
				"point cloud (colour; observations = keyframes seeing each point), or as an OctoMap .bt (each keyframe's\n"
				"points inserted from its camera: the space in front of them free; octovis, octomap_server). Files are\n"
				"written atomically. The map is only read (any vocabulary).",
				{"yesslam-map --map office.ysm", "yesslam-map --map office.ysm --scene office.3Dscene --ply office.ply --bt office.bt"});
			cl.text("map", "MAP.ysm", "the saved map (required)", &map, true);
			cl.text("scene", "FILE", "write the map as an MRPT .3Dscene", &scene);
			cl.text("ply", "FILE", "write the map points as a binary PLY", &ply);
			cl.text("bt", "FILE", "write an occupancy OctoMap (.bt) of the map points", &bt);
			cl.number("resolution", "M", "voxel size of --bt in metres (0.005..10, default 0.05)", &resolution);
			if (!cl.parse(argc, argv)) return 0;
			if (!(resolution >= 0.005 && resolution <= 10)) throw InputError("", "--resolution must be between 0.005 and 10 m");
			CSparseMap m;
			// Any vocabulary: the fingerprint check is for runs that localise in the map.
			const TMapFileInfo info = loadMapFile(map, m, 0);
			std::vector<std::string> names;
			const std::string share = shareDir();
			std::error_code ec;
			if (!share.empty() && std::filesystem::exists(share + "/models/yolo-fastest-1.1/coco.names", ec))
				names = readClassNames(share + "/models/yolo-fastest-1.1/coco.names");
			std::printf("map:          %s (format %u, %.1f MB, vocabulary %016llx)\n", map.c_str(), info.version, info.bytes / 1e6,
						static_cast<unsigned long long>(info.vocabularyFingerprint));
			std::fputs(formatMapSummary(summarizeMap(m, names)).c_str(), stdout);
			if (!scene.empty())
			{
				TTrajectory path;
				for (const auto& k : m.keyFramePoses())
					if (!k.bad) path.push_back(TStampedPose::fromPose(k.timestamp, k.pose));
				saveSceneAtomically(*buildMapScene(m, path), scene);
				std::printf("scene:        %s\n", scene.c_str());
			}
			if (!ply.empty())
			{
				writeDenseCloudPly(ply, mapPointCloud(m), names);
				std::printf("ply:          %s\n", ply.c_str());
			}
			if (!bt.empty())
			{
				const auto tree = mapOccupancy(m, resolution);
				writeOccupancyBt(bt, *tree);
				std::printf("bt:           %s (%zu leaves at %.3f m)\n", bt.c_str(), tree->getNumLeafNodes(), resolution);
			}
			return 0;
		});
}
