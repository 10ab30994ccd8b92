// The 2D occupancy grid for navigation (issue 67): the semantic OctoMap's band above the floor
// projected down, people never obstacles, and its files (MRPT's .gridmap, ROS map_server's .pgm +
// .yaml, the .png) read back with the same cells.
#include <gtest/gtest.h>
#include <mrpt/io/CFileGZInputStream.h>
#include <mrpt/maps/COccupancyGridMap2D.h>
#include <mrpt/serialization/CArchive.h>

#include <opencv2/imgcodecs.hpp>

#include <cstdio>
#include <filesystem>
#include <algorithm>
#include <set>

#include "TestUtils.h"
#include "mrpt_yesslam/dense/COccupancyGridBuilder.h"
#include "mrpt_yesslam/dense/DenseMapExport.h"
#include "mrpt_yesslam/io/Trajectory.h"
#include "mrpt_yesslam/jobs/SlamJob.h"
#include "mrpt_yesslam/mapio/GridMapFiles.h"
#include "mrpt_yesslam/util/Error.h"

using namespace mrpt_yesslam;
using namespace yesslam_test;
namespace fs = std::filesystem;

namespace
{
// What a cell of `g` holds at (x, y); a point outside the grid fails the test.
std::int8_t cellAt(const TOccupancyGrid2D& g, double x, double y)
{
	int i = -1, j = -1;
	EXPECT_TRUE(g.cellOf(x, y, i, j)) << x << " " << y;
	return i < 0 ? TOccupancyGrid2D::kUnknown : g.at(i, j);
}

// A room corner of 5 cm voxels, as the dense map's rays and hits leave it (occupancy threshold 0.8
// as the run's): the floor, the free space above it, a wall, a person, a table top, a shelf above
// the band and a surface seen once.
std::unique_ptr<CSemanticOcTree> roomCorner()
{
	auto tree = std::make_unique<CSemanticOcTree>(0.05);
	tree->setOccupancyThres(0.8);
	const auto hit = [&](double x, double y, double z, std::uint8_t label, int times = 4)
	{
		CSemanticOcTreeNode* n = nullptr;
		for (int k = 0; k < times; k++) n = tree->updateNode(octomap::point3d(float(x), float(y), float(z)), true);
		n->label = label;
	};
	for (double x = 0.025; x < 2; x += 0.05)
		for (double y = 0.025; y < 2; y += 0.05)
		{
			hit(x, y, 0.025, 0);
			for (double z = 0.125; z < 1.6; z += 0.05)
				tree->updateNode(octomap::point3d(float(x), float(y), float(z)), false);
		}
	for (double y = 0.025; y < 2; y += 0.05)
		for (double z = 0.025; z < 2; z += 0.05) hit(2.025, y, z, 0);    // the wall at x = 2
	for (double z = 0.125; z < 1.7; z += 0.05) hit(1.025, 1.025, z, 1);  // a person (COCO 0)
	hit(0.525, 1.525, 0.775, 61);                                        // a table top (COCO 60)
	for (double z = 1.575; z < 1.9; z += 0.05) hit(0.525, 0.525, z, 0);  // a shelf above the band
	hit(1.525, 0.525, 0.525, 0, 1);                                      // seen once: not confirmed
	tree->updateInnerOccupancy();
	return tree;
}
}  // namespace

TEST(Grid2D, TheBandAboveTheFloorIsProjectedAndPeopleAreNeverObstacles)
{
	const auto tree = roomCorner();
	COccupancyGridBuilder::TOptions o;  // band 0.15-1.5 m, 5 cm cells
	const std::vector<mrpt::math::TPoint3D> path{{-0.3, 1.0, 1.2}, {2.025, 0.325, 1.2}};
	const TOccupancyGrid2D g = COccupancyGridBuilder(o).build(*tree, {1}, path, 0.0, true);
	EXPECT_DOUBLE_EQ(g.resolution, 0.05);
	EXPECT_EQ(cellAt(g, 2.03, 1.0), TOccupancyGrid2D::kOccupied) << "the wall";
	EXPECT_EQ(cellAt(g, 0.53, 1.53), TOccupancyGrid2D::kOccupied) << "the table top";
	EXPECT_EQ(cellAt(g, 1.03, 1.03), TOccupancyGrid2D::kUnknown) << "a person is never an obstacle";
	EXPECT_EQ(cellAt(g, 0.53, 0.53), TOccupancyGrid2D::kFree) << "a shelf above the band";
	EXPECT_EQ(cellAt(g, 1.53, 0.53), TOccupancyGrid2D::kUnknown) << "a surface seen once is neither";
	EXPECT_EQ(cellAt(g, 1.33, 0.33), TOccupancyGrid2D::kFree) << "rays crossed the band over the floor";
	EXPECT_EQ(cellAt(g, -0.28, 1.0), TOccupancyGrid2D::kFree) << "the camera's path, never seen by a ray";
	EXPECT_EQ(cellAt(g, -0.28, 1.3), TOccupancyGrid2D::kUnknown) << "beyond the footprint, nothing seen";
	EXPECT_EQ(cellAt(g, 2.03, 0.33), TOccupancyGrid2D::kOccupied) << "a path over a seen obstacle leaves it";
	EXPECT_GT(g.count(TOccupancyGrid2D::kFree), 1000u);
	// Without the person's class among the dynamic ones, it is an obstacle.
	EXPECT_EQ(cellAt(COccupancyGridBuilder(o).build(*tree, {}, path, 0.0, true), 1.03, 1.03),
			  TOccupancyGrid2D::kOccupied);
	// The band moves with the floor and with its options.
	const TOccupancyGrid2D raised = COccupancyGridBuilder(o).build(*tree, {1}, path, 0.5, true);
	EXPECT_EQ(cellAt(raised, 0.53, 0.53), TOccupancyGrid2D::kOccupied) << "the shelf is in a band 0.65-2.0 m";
	o.minHeight = 0.8;
	EXPECT_EQ(cellAt(COccupancyGridBuilder(o).build(*tree, {1}, path, 0.0, true), 0.53, 1.53), TOccupancyGrid2D::kFree)
		<< "the table top is below a band from 0.8 m";
	o.minHeight = 1.5;
	EXPECT_THROW(COccupancyGridBuilder(o).build(*tree, {1}, path, 0.0, true), std::invalid_argument);
	// Cells larger than the voxels: the one-voxel wall is in every cell it overlaps (a cell took only
	// the voxel at its centre, and the wall between two centres was lost).
	o = COccupancyGridBuilder::TOptions();
	o.resolution = 0.1;
	const TOccupancyGrid2D coarse = COccupancyGridBuilder(o).build(*tree, {1}, path, 0.0, true);
	for (double y = 0.05; y < 1.95; y += 0.1)
		EXPECT_EQ(cellAt(coarse, 2.03, y), TOccupancyGrid2D::kOccupied) << "the wall at y " << y;
	// A pose far astray asks for no gigabytes: refused.
	EXPECT_THROW(COccupancyGridBuilder(o).build(*tree, {1}, {{5e4, 5e4, 1}}, 0.0, true), std::invalid_argument);
}

TEST(Grid2D, TheFilesReadBackWithTheSameCellsInMrptAndRos)
{
	const auto tree = roomCorner();
	const std::vector<mrpt::math::TPoint3D> path{{-0.3, 1.0, 1.2}, {0.3, 1.0, 1.2}, {0.6, 0.8, 1.2}};
	const TOccupancyGrid2D g =
		COccupancyGridBuilder(COccupancyGridBuilder::TOptions()).build(*tree, {1}, path, 0, true);
	TempDir d("grid_files");
	writeGridMapFiles(d / "map_2d", g, path);
	// ROS map_server's pair.
	const TOccupancyGrid2D ros = readRosMap(d / "map_2d.yaml");
	EXPECT_EQ(ros.width, g.width);
	EXPECT_EQ(ros.height, g.height);
	EXPECT_NEAR(ros.originX, g.originX, 1e-6);
	EXPECT_NEAR(ros.originY, g.originY, 1e-6);
	EXPECT_NEAR(ros.resolution, g.resolution, 1e-9);
	EXPECT_EQ(ros.cells, g.cells);
	// MRPT's grid, read as MRPT programs read it: every cell at its place with its state.
	mrpt::maps::COccupancyGridMap2D m;
	{
		mrpt::io::CFileGZInputStream f(d / "map_2d.gridmap");
		auto a = mrpt::serialization::archiveFrom(f);
		a >> m;
	}
	EXPECT_NEAR(m.getResolution(), g.resolution, 1e-6);
	std::size_t same = 0;
	for (int j = 0; j < g.height; j++)
		for (int i = 0; i < g.width; i++)
		{
			const float pFree =
				m.getPos(float(g.originX + (i + 0.5) * g.resolution), float(g.originY + (j + 0.5) * g.resolution));
			const std::int8_t v = pFree < 0.35f
									  ? TOccupancyGrid2D::kOccupied
									  : (pFree > 0.65f ? TOccupancyGrid2D::kFree : TOccupancyGrid2D::kUnknown);
			same += v == g.at(i, j);
		}
	EXPECT_EQ(same, g.cells.size());
	// The picture: a whole number of pixels a cell, the path drawn in red.
	const cv::Mat png = cv::imread(d / "map_2d.png", cv::IMREAD_COLOR);
	ASSERT_FALSE(png.empty());
	EXPECT_EQ(png.cols % g.width, 0);
	EXPECT_EQ(png.cols / g.width, png.rows / g.height);
	std::size_t red = 0;
	for (int v = 0; v < png.rows; v++)
		for (int u = 0; u < png.cols; u++)
		{
			const auto& c = png.at<cv::Vec3b>(v, u);
			red += c[2] > 200 && c[1] < 80 && c[0] < 80;
		}
	EXPECT_GT(red, 20u);
	// A description that is not a map's is refused in one line naming it.
	writeText(d / "bad.yaml", "image: x.pgm\nresolution: 0.05\n");
	try
	{
		readRosMap(d / "bad.yaml");
		ADD_FAILURE() << "accepted";
	}
	catch (const InputError& e)
	{
		EXPECT_NE(std::string(e.what()).find("bad.yaml: no 'origin'"), std::string::npos) << e.what();
	}
}

// On both real cameras (the Bonn crowd slice, an Xtion with people walking close; TUM fr1_rpy, a
// Kinect turning in place over a desk; test data only, ../shared/data/*/SOURCE.md), default
// configuration, sequential, the first 150 frames: the grid the run writes has the camera's path
// free and the static surfaces of the dense cloud in the band occupied within a cell.
TEST(Grid2D, OnRealFramesThePathIsFreeAndTheStaticSurfacesAreObstacles)
{
	for (const std::string name : {"bonn_crowd_dev", "tum_fr1_rpy_dev"})
	{
		TempDir d("grid_real");
		TSlamJobOptions o;
		o.input = sharedFile("data/" + name);
		o.outDir = d.path();
		o.maxFrames = 150;
		o.slam.system.parallel = false;
		o.slam.loop.detection.enabled = false;
		const TSlamJobSummary s = runSlamJob(o);
		ASSERT_TRUE(s.dense.gridProblem.empty()) << s.dense.gridProblem;
		EXPECT_TRUE(s.dense.gridFloorSeen) << name;
		const TOccupancyGrid2D g = readRosMap(d / "map_2d.yaml");
		EXPECT_EQ(g.count(TOccupancyGrid2D::kOccupied), s.dense.gridOccupied);
		std::set<std::pair<int, int>> path;
		for (const auto& p : readTumTrajectory(d / "trajectory.txt"))
		{
			int i, j;
			ASSERT_TRUE(g.cellOf(p.tx, p.ty, i, j)) << name << ": the path leaves the grid";
			path.insert({i, j});
		}
		std::size_t pathFree = 0;
		for (const auto& [i, j] : path) pathFree += g.at(i, j) == TOccupancyGrid2D::kFree;
		// The dense cloud's static points in the band (label 1 is a person: never in the cloud anyway).
		const COccupancyGridBuilder::TOptions go;
		const TDenseCloud cloud = readDenseCloudPly(d / "dense_cloud.ply");
		std::set<std::pair<int, int>> surface;
		for (std::size_t k = 0; k < cloud.size(); k++)
		{
			const auto& p = cloud.xyz[k];
			int i, j;
			if (cloud.label[k] != 1 && p.z >= go.minHeight && p.z <= go.maxHeight && g.cellOf(p.x, p.y, i, j))
				surface.insert({i, j});
		}
		std::size_t occupied = 0;
		for (const auto& [i, j] : surface)
		{
			bool near = false;
			for (int dj = -1; dj <= 1; dj++)
				for (int di = -1; di <= 1; di++)
					near |= i + di >= 0 && j + dj >= 0 && i + di < g.width && j + dj < g.height &&
							g.at(i + di, j + dj) == TOccupancyGrid2D::kOccupied;
			occupied += near;
		}
		std::printf("%s: path free %zu/%zu, static surface cells occupied %zu/%zu\n", name.c_str(), pathFree,
					path.size(), occupied, surface.size());
		EXPECT_GE(pathFree, 0.98 * path.size()) << name;
		EXPECT_GE(occupied, 0.8 * surface.size()) << name;
	}
}

// yesslam-map makes the grid from a saved map or from a run's map.ot, with other band and cell
// options, into folders it makes; bad options are refused before anything is written.
TEST(Grid2D, YesslamMapMakesTheGridFromASavedMapOrAnOctoMap)
{
	TempDir d("grid_tool");
	const auto run = runTool("yesslam", {"--input", walkingSequence60(), "--out", d / "run", "--save-map",
										 d / "maps/m.ysm", "--sequential", "--quiet"});
	ASSERT_EQ(run.exitCode, 0) << run.err;
	const TOccupancyGrid2D ran = readRosMap(d / "run/map_2d.yaml");
	// Every occupied cell of the run's grid, at its place in another grid.
	const auto occupiedIn = [&](const TOccupancyGrid2D& other)
	{
		std::size_t n = 0;
		for (int j = 0; j < ran.height; j++)
			for (int i = 0; i < ran.width; i++)
			{
				int oi, oj;
				n += ran.at(i, j) == TOccupancyGrid2D::kOccupied &&
					 other.cellOf(ran.originX + (i + 0.5) * ran.resolution, ran.originY + (j + 0.5) * ran.resolution,
								  oi, oj) &&
					 other.at(oi, oj) == TOccupancyGrid2D::kOccupied;
			}
		return n;
	};
	ASSERT_GT(ran.count(TOccupancyGrid2D::kOccupied), 100u);
	for (const auto& input :
		 std::vector<std::vector<std::string>>{{"--map", d / "maps/m.ysm"}, {"--octree", d / "run/map.ot"}})
	{
		std::vector<std::string> args = input;
		args.insert(args.end(), {"--grid", d / "nav/sub/a"});
		const auto r = runTool("yesslam-map", args);
		ASSERT_EQ(r.exitCode, 0) << r.err;
		EXPECT_NE(r.out.find("grid:         " + (d / "nav/sub/a")), std::string::npos) << r.out;
		if (input[0] == "--octree")  // the run's frame and path come from its trajectory.txt
		{
			EXPECT_NE(r.out.find("the frame and path of " + (d / "run/trajectory.txt")), std::string::npos) << r.out;
		}
		const TOccupancyGrid2D same = readRosMap(d / "nav/sub/a.yaml");
		EXPECT_EQ(same.count(TOccupancyGrid2D::kOccupied), ran.count(TOccupancyGrid2D::kOccupied)) << input[0];
		EXPECT_EQ(occupiedIn(same), ran.count(TOccupancyGrid2D::kOccupied)) << input[0];
	}
	// A lower band (a robot 0.5 m tall) and coarser cells.
	const auto low = runTool("yesslam-map", {"--octree", d / "run/map.ot", "--grid", d / "nav/low", "--grid-max-height",
											 "0.5", "--grid-resolution", "0.1"});
	ASSERT_EQ(low.exitCode, 0) << low.err;
	const TOccupancyGrid2D lowGrid = readRosMap(d / "nav/low.yaml");
	EXPECT_DOUBLE_EQ(lowGrid.resolution, 0.1);
	EXPECT_NE(readText(d / "nav/low.yaml").find("band 0.150-0.500 m above the floor"), std::string::npos);
	EXPECT_GT(lowGrid.count(TOccupancyGrid2D::kOccupied), 0u);
	EXPECT_LT(lowGrid.count(TOccupancyGrid2D::kOccupied), ran.count(TOccupancyGrid2D::kOccupied))
		<< "fewer cells of four times the area, in a lower band";
	fs::create_directories(d / "optical");
	fs::copy_file(d / "run/map.ot", d / "optical/map.ot");
	writeText(d / "optical/trajectory.txt", "# world frame: optical (the first keyframe's camera)\n");
	// Refused in one line, nothing written.
	for (const auto& [args, fragment] : std::vector<std::pair<std::vector<std::string>, std::string>>{
			 {{"--octree", d / "run/map.ot", "--grid", d / "bad/c", "--dynamic-classes", "persn"}, "'persn'"},
			 {{"--octree", d / "run/map.ot", "--grid", d / "bad/c", "--grid-min-height", "2"}, "--grid-max-height"},
			 {{"--octree", d / "run/map.ot", "--scene", d / "bad/c.3Dscene"}, "need the map"},
			 {{"--octree", d / "run/trajectory.txt", "--grid", d / "bad/c"}, "trajectory.txt"},
			 {{"--grid", d / "bad/c"}, "give one of --map"},
			 // Beside a run in the optical frame (its trajectory.txt says so): refused before --bt is written.
			 {{"--octree", d / "optical/map.ot", "--bt", d / "bad/x.bt", "--grid", d / "bad/c"}, "optical frame"}})
	{
		const auto r = runTool("yesslam-map", args);
		EXPECT_EQ(r.exitCode, 1) << r.out;
		EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
		EXPECT_NE(r.err.find(fragment), std::string::npos) << r.err;
		EXPECT_FALSE(fs::exists(d / "bad")) << r.err;
	}
}
