// yesslam-map: what a saved map (.ysm, yesslam --save-map) holds, and the map as a scene, a point
// cloud or an occupancy octree.
#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <map>
#include <optional>
#include <set>

#include "mrpt_yesslam/dense/COccupancyGridBuilder.h"
#include "mrpt_yesslam/dense/DenseMapExport.h"
#include "mrpt_yesslam/detection/CObjectDetector.h"
#include "mrpt_yesslam/mapio/MapFile.h"
#include "mrpt_yesslam/mapio/GridMapFiles.h"
#include "mrpt_yesslam/mapio/MapSummary.h"
#include "mrpt_yesslam/io/SceneExport.h"
#include "mrpt_yesslam/io/Trajectory.h"
#include "mrpt_yesslam/system/SlamExport.h"
#include "mrpt_yesslam/util/AtomicFile.h"
#include "mrpt_yesslam/util/CommandLine.h"
#include "mrpt_yesslam/util/Error.h"
#include "mrpt_yesslam/util/ShareDir.h"
#include "mrpt_yesslam/util/TextParsing.h"

using namespace mrpt_yesslam;

namespace
{
// The 2D grid of --grid: the octree's band as the options say, the dynamic classes never occupied;
// `cams` gets the path's positions. Throws InputError naming `input` when the map cannot give one.
TOccupancyGrid2D makeGrid(const std::string& input, const CSemanticOcTree* octree, const TWorldFrame& frame,
						  const TTrajectory& path, const COccupancyGridBuilder::TOptions& go,
						  const std::string& dynamicClasses, const std::vector<std::string>& names,
						  std::vector<mrpt::math::TPoint3D>& cams)
{
	if (!octree)
		throw InputError(input,
						 "has no semantic octree: a 2D grid is made from the dense map's (a run without "
						 "--no-dense-map)");
	if (frame.kind != TWorldFrame::EKind::ZUp)
		throw InputError(input, "is in the optical frame: a 2D grid needs the z-up world frame");
	std::set<std::uint8_t> dynamicLabels;
	for (const auto& c : splitFields(dynamicClasses))
	{
		const auto it = std::find(names.begin(), names.end(), c);
		if (it == names.end())
			throw InputError("", "--dynamic-classes: '" + c + "' is not a COCO class name of the shipped detector");
		dynamicLabels.insert(static_cast<std::uint8_t>(it - names.begin() + 1));
	}
	for (const auto& p : path) cams.emplace_back(p.tx, p.ty, p.tz);
	// A map whose run saw no floor has its origin at the first camera: the floor is assumed below it.
	const double floorZ = frame.floorSeen ? 0.0 : -go.cameraHeight;
	try
	{
		TOccupancyGrid2D g = COccupancyGridBuilder(go).build(*octree, dynamicLabels, cams, floorZ, frame.floorSeen);
		if (g.width == 0)
			throw std::invalid_argument("nothing was seen in the grid's height band and there is no path");
		return g;
	}
	catch (const std::invalid_argument& e)
	{
		throw InputError(input, e.what());
	}
}
}  // namespace

int main(int argc, char** argv)
{
	return runTool(
		"yesslam-map",
		[&]() -> int
		{
			std::string map, octreeIn, scene, ply, bt, ot, grid, dynamicClasses = "person";
			double resolution = 0.05;
			COccupancyGridBuilder::TOptions go;
			CommandLine cl("yesslam-map",
						   "yesslam-map (--map MAP.ysm | --octree MAP.ot) [--scene OUT.3Dscene] [--ply OUT.ply] [--bt "
						   "OUT.bt [--resolution M]] [--ot OUT.ot] [--grid BASE [--grid-min-height M] "
						   "[--grid-max-height M] [--grid-resolution M]]",
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
						   "front of them free). --grid projects the semantic OctoMap (of the map, or a run's map.ot "
						   "given with\n"
						   "--octree) into a 2D occupancy grid for navigation, as yesslam's map_2d.* with other band "
						   "and cell options:\n"
						   "BASE.gridmap (MRPT COccupancyGridMap2D), BASE.pgm + BASE.yaml (ROS map_server), BASE.png "
						   "(with the keyframes'\n"
						   "path). Files are written atomically; their folders are made. The map is only read (any "
						   "vocabulary).",
						   {"yesslam-map --map office.ysm",
							"yesslam-map --map office.ysm --scene office.3Dscene --ply office.ply --bt office.bt",
							"yesslam-map --octree run/map.ot --grid nav/office --grid-max-height 0.5"});
			cl.text("map", "MAP.ysm", "the saved map", &map);
			cl.text(
				"octree", "MAP.ot",
				"instead of --map: a semantic OctoMap written by yesslam (map.ot, z-up world frame with the floor at "
				"z = 0), for --grid and --bt",
				&octreeIn);
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
			cl.text("grid", "BASE",
					"write the 2D occupancy grid as BASE.gridmap, BASE.pgm, BASE.yaml and BASE.png (people never "
					"occupied)",
					&grid);
			cl.number("grid-min-height", "M", "bottom of the grid's height band, metres above the floor (default 0.15)",
					  &go.minHeight);
			cl.number("grid-max-height", "M",
					  "top of the grid's height band, metres above the floor: the robot's height (default 1.5)",
					  &go.maxHeight);
			cl.number("grid-resolution", "M", "cell size of the grid, metres (0.01..1, default 0.05)", &go.resolution);
			cl.text("dynamic-classes", "LIST",
					"comma-separated class names never occupied in the grid (default person, as [Detector] "
					"dynamicClasses)",
					&dynamicClasses);
			if (!cl.parse(argc, argv)) return 0;
			if (!(resolution >= 0.005 && resolution <= 10))
				throw InputError("", "--resolution must be between 0.005 and 10 m");
			if (map.empty() == octreeIn.empty()) throw InputError("", "give one of --map MAP.ysm and --octree MAP.ot");
			if (!(go.resolution >= 0.01 && go.resolution <= 1))
				throw InputError("", "--grid-resolution must be between 0.01 and 1 m");
			if (!(go.maxHeight > go.minHeight))
				throw InputError("", "--grid-max-height must be above --grid-min-height");
			if (!octreeIn.empty() && (!scene.empty() || !ply.empty() || !ot.empty()))
				throw InputError(octreeIn,
								 "an OctoMap alone gives --grid and --bt only (--scene, --ply and --ot need "
								 "the map: --map)");
			CSparseMap m;
			std::unique_ptr<CSemanticOcTree> octree;
			TMapFileInfo info;
			if (!map.empty())
				// Any vocabulary: the fingerprint check is for runs that localise in the map.
				info = loadMapFile(map, m, 0, &octree);
			else
				octree = CSemanticOcTree::readFile(octreeIn);
			const std::string input = map.empty() ? octreeIn : map;
			// The path in the exports' frame: the keyframes' of a map; beside a run's map.ot, its
			// trajectory.txt, whose header also says the frame (a .ot itself does not).
			TTrajectory path;
			for (const auto& k : m.keyFramePoses())
				if (!k.bad) path.push_back(TStampedPose::fromPose(k.timestamp, info.worldFrame.worldFromMap + k.pose));
			std::string frameNote;
			if (!octreeIn.empty())
			{
				const auto beside = std::filesystem::path(octreeIn).parent_path() / "trajectory.txt";
				std::error_code exists;
				if (std::filesystem::is_regular_file(beside, exists))
				{
					const std::string head = readTextFile(beside.string()).substr(0, 2000);
					info.worldFrame.kind = head.find("world frame: optical") != std::string::npos
											   ? TWorldFrame::EKind::Optical
											   : TWorldFrame::EKind::ZUp;
					info.worldFrame.floorSeen = head.find("levelled by the floor plane") != std::string::npos;
					path = readTumTrajectory(beside.string());
					frameNote = "the frame and path of " + beside.string();
				}
				else
				{
					// No run beside it: taken as yesslam's z-up frame with the floor at z = 0.
					info.worldFrame.kind = TWorldFrame::EKind::ZUp;
					info.worldFrame.floorSeen = true;
					frameNote = "no trajectory.txt beside it: taken as z-up with the floor at z = 0, no path";
				}
			}
			std::vector<std::string> names;
			const std::string share = shareDir();
			std::error_code ec;
			if (!share.empty() && std::filesystem::exists(share + "/models/yolo-fastest-1.1/coco.names", ec))
				names = readClassNames(share + "/models/yolo-fastest-1.1/coco.names");
			// The grid, made before anything is printed or written: a bad option or a map that cannot
			// give one writes nothing.
			std::optional<TOccupancyGrid2D> gridMap;
			std::vector<mrpt::math::TPoint3D> cams;
			if (!grid.empty())
				gridMap = makeGrid(input, octree.get(), info.worldFrame, path, go, dynamicClasses, names, cams);
			if (!map.empty())
			{
				std::printf("map:          %s (format %u, %.1f MB, vocabulary %016llx)\n", map.c_str(), info.version,
							info.bytes / 1e6, static_cast<unsigned long long>(info.vocabularyFingerprint));
				std::fputs(formatMapSummary(summarizeMap(m, names, info.worldFrame.worldFromMap)).c_str(), stdout);
				const std::string frame = info.worldFrame.describe();
				std::printf("exports in:   %s\n", frame.substr(0, frame.find('\n')).c_str());
			}
			else
				std::printf("octree file:  %s (%s)\n", octreeIn.c_str(), frameNote.c_str());
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
				makeParentFolder(ot);
				writeSemanticOcTree(ot, *octree);
				std::printf("ot:           %s\n", ot.c_str());
			}
			if (!scene.empty())
			{
				makeParentFolder(scene);
				saveSceneAtomically(*buildMapScene(m, path, info.worldFrame.worldFromMap), scene);
				std::printf("scene:        %s\n", scene.c_str());
			}
			if (!ply.empty())
			{
				makeParentFolder(ply);
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
				makeParentFolder(bt);
				const std::size_t leaves = writeOccupancyBt(bt, tree);
				std::printf("bt:           %s (%zu leaves at %.3f m, %s)\n", bt.c_str(), leaves, tree.getResolution(),
							octree ? "the saved semantic octree" : "from the map points");
			}
			if (gridMap)
			{
				const TOccupancyGrid2D& g = *gridMap;
				makeParentFolder(grid + ".gridmap");
				writeGridMapFiles(grid, g, cams);
				std::printf(
					"grid:         %s.{gridmap,pgm,yaml,png} (%d x %d cells of %.3f m; %zu occupied, %zu free, "
					"%zu unknown; band %.2f-%.2f m above the floor%s)\n",
					grid.c_str(), g.width, g.height, g.resolution, g.count(TOccupancyGrid2D::kOccupied),
					g.count(TOccupancyGrid2D::kFree), g.count(TOccupancyGrid2D::kUnknown), go.minHeight, go.maxHeight,
					g.floorSeen ? "" : ", no floor seen: assumed [Grid2D] cameraHeight below the first camera");
			}
			return 0;
		});
}
