// Map reuse (issue 17) through the yesslam CLI: a generated room is mapped and saved; a second,
// differently seeded pass through the same room (another camera path, people elsewhere, starting
// 0.4 m from where the first began) loads the map and localises in it, with its trajectory in the
// saved map's frame; --localize-only leaves the map byte for byte as it was; damaged, cut, foreign,
// newer and other-vocabulary files are refused in one line.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "TestUtils.h"
#include <octomap/OcTree.h>

#include "mrpt_yesslam/data/CSparseMap.h"
#include "mrpt_yesslam/dense/CSemanticOcTree.h"
#include "mrpt_yesslam/dense/DenseMapExport.h"
#include "mrpt_yesslam/mapio/MapFile.h"
#include "mrpt_yesslam/io/Trajectory.h"
#include "mrpt_yesslam/io/WorldFrame.h"
#include "mrpt_yesslam/util/BinaryIO.h"

using namespace yesslam_test;
namespace fs = std::filesystem;

namespace
{
std::string pass(const std::string& preset, std::uint32_t seed)
{
	mrpt_yesslam::TSimOptions o;
	o.preset = preset;
	o.seed = seed;
	o.roomSeed = 7;
	o.frames = 150;
	return cachedSequence("mapreuse_" + preset + "_r7_s" + std::to_string(seed) + "_150", o);
}

// Rewrites a map file's header field at `offset` and its checksum, so only that field is wrong.
void patchMapFile(const std::string& path, std::size_t offset, const void* value, std::size_t n)
{
	std::string buf = readText(path);
	std::memcpy(buf.data() + offset, value, n);
	const std::uint64_t sum = mrpt_yesslam::binio::checksum(buf.data(), buf.size() - 8);
	std::memcpy(buf.data() + buf.size() - 8, &sum, 8);
	std::ofstream(path, std::ios::binary) << buf;
}
}  // namespace

TEST(MapReuse, ASecondPassLocalisesInTheSavedMapInItsFrameAndLeavesItUnchanged)
{
	TempDir d("map_reuse");
	const std::string first = pass("walking_xyz", 7);
	const std::string second = pass("walking_halfsphere", 8);
	const std::vector<std::string> common = {"--sequential", "--quiet", "--no-dense-map"};
	auto run = [&](std::vector<std::string> args)
	{
		args.insert(args.end(), common.begin(), common.end());
		return runTool("yesslam", args);
	};
	// The second pass starts 30 frames in (0.4 m from where the first pass began, turned 20 degrees).
	auto secondPass = [&](std::vector<std::string> args)
	{
		args.insert(args.end(), {"--input", second, "--skip-frames", "30"});
		return run(args);
	};
	const auto mapped = run({"--input", first, "--out", d / "map", "--save-map", d / "room.ysm"});
	ASSERT_EQ(mapped.exitCode, 0) << mapped.err;
	EXPECT_NE(mapped.out.find("map saved:"), std::string::npos) << mapped.out;
	ASSERT_TRUE(fs::exists(d / "room.ysm"));

	// The saved map loads into the same points and poses, placed by the export frame it keeps.
	mrpt_yesslam::CSparseMap loaded;
	const auto info = mrpt_yesslam::loadMapFile(d / "room.ysm", loaded, 0);
	const auto kfTraj = mrpt_yesslam::readTumTrajectory(d / "map/keyframes.txt");
	ASSERT_EQ(loaded.numKeyFrames(), kfTraj.size());
	std::size_t k = 0;
	for (const auto& kp : loaded.keyFramePoses())
		if (!kp.bad)
		{
			const auto written = kfTraj[k++].asPose();
			EXPECT_LT((written - (info.worldFrame.worldFromMap + kp.pose)).norm(), 1e-6) << "keyframe " << kp.id;
		}

	const auto loc = secondPass(
		{"--out", d / "loc", "--load-map", d / "room.ysm", "--localize-only", "--save-map", d / "again.ysm"});
	ASSERT_EQ(loc.exitCode, 0) << loc.err;
	EXPECT_NE(loc.out.find("localisation only"), std::string::npos) << loc.out;
	// Localisation only: the map written back is the map read, byte for byte.
	EXPECT_EQ(readText(d / "room.ysm"), readText(d / "again.ysm"));

	// The first pose within a few frames, by relocalisation.
	std::istringstream csv(readText(d / "loc/frames.csv"));
	std::string line;
	std::getline(csv, line);
	int firstTracked = -1, n = 0;
	while (std::getline(csv, line) && firstTracked < 0)
	{
		std::vector<std::string> c;
		std::stringstream ls(line);
		for (std::string x; std::getline(ls, x, ',');) c.push_back(x);
		ASSERT_GT(c.size(), 4u) << line;
		if (c[2] == "1")
		{
			firstTracked = n;
			EXPECT_EQ(c[4], "1") << "placed by relocalisation";
		}
		n++;
	}
	ASSERT_GE(firstTracked, 0);
	EXPECT_LE(firstTracked, 3);

	// In the saved map's frame: the first pass's first camera pose is the map's origin, and both
	// passes' ground truths are in the same room frame, so without any alignment the second pass's
	// poses must be T_world_map T_first0^-1 T_second(t), with the export frame (T_world_map) the
	// first pass wrote and saved with the map: the second pass exports in it too (issue 30 item 4).
	const auto gt1 = mrpt_yesslam::readTumTrajectory(first + "/groundtruth.txt");
	const auto gt2 = mrpt_yesslam::readTumTrajectory(second + "/groundtruth.txt");
	const auto worldFromMap = mrpt_yesslam::readWorldFromMap(d / "map/trajectory.txt");
	ASSERT_TRUE(worldFromMap.has_value());
	const auto locFrame = mrpt_yesslam::readWorldFromMap(d / "loc/trajectory.txt");
	ASSERT_TRUE(locFrame.has_value());
	EXPECT_LT((locFrame->asVectorVal() - worldFromMap->asVectorVal()).norm(), 1e-8)
		<< "the loaded map's export frame is kept";
	const auto origin = gt1.front().asPose();
	auto errorInMapFrame = [&](const std::string& trajectory)
	{
		const auto est = mrpt_yesslam::readTumTrajectory(trajectory);
		double sum = 0;
		std::size_t used = 0;
		for (const auto& e : est)
			for (const auto& g : gt2)
				if (std::abs(g.t - e.t) < 1e-4)
				{
					const auto expected = *worldFromMap + (g.asPose() - origin);
					const auto got = e.asPose();
					sum += std::pow(got.x() - expected.x(), 2) + std::pow(got.y() - expected.y(), 2) +
						   std::pow(got.z() - expected.z(), 2);
					used++;
				}
		EXPECT_GT(used, 100u);
		return std::sqrt(sum / std::max<std::size_t>(1, used));
	};
	const double inMap = errorInMapFrame(d / "loc/trajectory.txt");
	std::printf("localisation only: first pose at frame %d, unaligned RMSE in the map's frame %.1f mm\n", firstTracked,
				1000 * inMap);
	// Localisation only adds no keyframes: where this pass looks at the room from farther away than
	// the first pass did, its pose rests on the old map's far points alone (measured 29 mm here; the
	// same pass extending the map: 9 mm, below).
	EXPECT_LT(inMap, 0.06) << "unaligned RMSE in the map's frame";

	// Without the map the same pass has its own frame (its first camera pose): 0.4 m off the map's.
	const auto alone = secondPass({"--out", d / "alone"});
	ASSERT_EQ(alone.exitCode, 0) << alone.err;
	const double own = errorInMapFrame(d / "alone/trajectory.txt");
	std::printf("without the map: %.1f mm from the map's frame\n", 1000 * own);
	EXPECT_GT(own, 0.2);

	// Extending the map (no --localize-only): new keyframes get ids after the saved ones and the
	// map saved afterwards holds both passes.
	const auto ext = secondPass({"--out", d / "ext", "--load-map", d / "room.ysm", "--save-map", d / "bigger.ysm"});
	ASSERT_EQ(ext.exitCode, 0) << ext.err;
	mrpt_yesslam::CSparseMap bigger;
	mrpt_yesslam::loadMapFile(d / "bigger.ysm", bigger, 0);
	EXPECT_GT(bigger.numKeyFrames(), loaded.numKeyFrames());
	const auto oldIds = loaded.keyFrameIds();
	for (auto id : bigger.keyFrameIds())
		if (std::find(oldIds.begin(), oldIds.end(), id) == oldIds.end())
		{
			EXPECT_GT(id, oldIds.back());
		}
	const double extended = errorInMapFrame(d / "ext/trajectory.txt");
	std::printf("extending the map: %.1f mm in its frame, %zu -> %zu keyframes\n", 1000 * extended,
				loaded.numKeyFrames(), bigger.numKeyFrames());
	EXPECT_LT(extended, 0.03);
}

TEST(MapReuse, ARunOnALoadedMapContinuesItsSemanticOctree)
{
	// The map's octree is where the next run's dense map starts: after a short second pass (the
	// last 20 frames), map.ot still holds what the first pass saw; alone, the same pass has about
	// half of it (measured: 12,894 of 13,077 occupied voxels kept; 6,608 alone).
	TempDir d("map_reuse_octree");
	const std::string seq = walkingSequence60();
	const std::vector<std::string> common = {"--input", seq, "--sequential", "--quiet"};
	auto run = [&](std::vector<std::string> args)
	{
		args.insert(args.end(), common.begin(), common.end());
		return runTool("yesslam", args);
	};
	const auto first = run({"--out", d / "first", "--save-map", d / "m.ysm"});
	ASSERT_EQ(first.exitCode, 0) << first.err;
	const auto merged = run({"--out", d / "merged", "--load-map", d / "m.ysm", "--skip-frames", "40"});
	ASSERT_EQ(merged.exitCode, 0) << merged.err;
	EXPECT_NE(merged.out.find("continues the loaded map's"), std::string::npos) << merged.out;
	const auto alone = run({"--out", d / "alone", "--skip-frames", "40"});
	ASSERT_EQ(alone.exitCode, 0) << alone.err;

	const auto a = mrpt_yesslam::CSemanticOcTree::readFile(d / "first/map.ot");
	const auto m = mrpt_yesslam::CSemanticOcTree::readFile(d / "merged/map.ot");
	const auto b = mrpt_yesslam::CSemanticOcTree::readFile(d / "alone/map.ot");
	auto occupied = [](const mrpt_yesslam::CSemanticOcTree& t)
	{
		std::size_t n = 0;
		for (auto it = t.begin_leafs(); it != t.end_leafs(); ++it) n += t.isNodeOccupied(*it);
		return n;
	};
	std::size_t kept = 0, total = 0, labelled = 0, labelKept = 0;
	for (auto it = a->begin_leafs(); it != a->end_leafs(); ++it)
	{
		if (!a->isNodeOccupied(*it)) continue;
		total++;
		const auto* n = m->search(it.getCoordinate());
		const bool occ = n && m->isNodeOccupied(n);
		kept += occ;
		if (it->label > 0) labelled++, labelKept += occ && n->label == it->label;
	}
	std::printf("first pass %zu occupied, %zu of them occupied after the second; alone %zu\n", total, kept,
				occupied(*b));
	ASSERT_GT(total, 1000u);
	EXPECT_GT(kept, total * 8 / 10);
	EXPECT_GT(labelKept, labelled * 7 / 10);
	EXPECT_LT(occupied(*b), kept * 3 / 4);
}

TEST(MapReuse, APassNeverLocalisedInTheMapIsAnErrorWithNoFakePoses)
{
	// A map of the walking room, and a pass through somewhere else (frames of smooth gradients that
	// nothing in the map looks like): before, it exited 0 with an identity pose per frame and an ATE
	// over them.
	TempDir d("map_reuse_never");
	const auto mapped = runTool("yesslam", {"--input", walkingSequence60(), "--out", d / "map", "--save-map",
											d / "room.ysm", "--sequential", "--quiet", "--no-dense-map"});
	ASSERT_EQ(mapped.exitCode, 0) << mapped.err;
	writeTumFolder(d / "elsewhere", makeSyntheticFrames(12, 640, 480));
	const auto r = runTool("yesslam", {"--input", d / "elsewhere", "--out", d / "loc", "--load-map", d / "room.ysm",
									   "--localize-only", "--quiet", "--detector", "none"});
	EXPECT_EQ(r.exitCode, 1) << r.out;
	EXPECT_NE(r.err.find("never localised in the map"), std::string::npos) << r.err;
	EXPECT_NE(r.err.find("room.ysm"), std::string::npos) << r.err;
	EXPECT_EQ(r.err.find('\n'), r.err.size() - 1) << "one line: " << r.err;
	EXPECT_TRUE(mrpt_yesslam::readTumTrajectory(d / "loc/trajectory.txt").empty());
	EXPECT_TRUE(mrpt_yesslam::readTumTrajectory(d / "loc/trajectory_online.txt").empty());
	EXPECT_FALSE(fs::exists(d / "loc/eval.json"));
	// frames.csv lists every frame, each without a pose.
	std::istringstream csv(readText(d / "loc/frames.csv"));
	std::string line;
	std::getline(csv, line);
	EXPECT_EQ(line.substr(line.rfind(',') + 1), "pose");
	std::size_t rows = 0;
	while (std::getline(csv, line))
	{
		rows++;
		EXPECT_EQ(line.substr(line.rfind(',') + 1), "none") << line;
	}
	EXPECT_EQ(rows, 12u);
}

TEST(MapReuse, ALocaliseOnlyRunSavesTheMapItLoadedOctreeIncluded)
{
	// Issue 30 item 2: the re-saved map lost its semantic OctoMap (localisation runs build no dense
	// map, and the loaded octree was not kept): yesslam-map then said the run had no dense map.
	TempDir d("map_reuse_resave");
	const auto mapped = runTool("yesslam", {"--input", walkingSequence60(), "--out", d / "map", "--save-map",
											d / "a.ysm", "--sequential", "--quiet"});
	ASSERT_EQ(mapped.exitCode, 0) << mapped.err;
	const auto loc = runTool("yesslam", {"--input", walkingSequence60(), "--out", d / "loc", "--load-map", d / "a.ysm",
										 "--localize-only", "--save-map", d / "b.ysm", "--sequential", "--quiet"});
	ASSERT_EQ(loc.exitCode, 0) << loc.err;
	const std::string a = readText(d / "a.ysm"), b = readText(d / "b.ysm");
	ASSERT_FALSE(a.empty());
	EXPECT_TRUE(a == b) << "the localise-only run must save the map it loaded, byte for byte (" << a.size() << " vs "
						<< b.size() << " bytes)";
	const auto info = runTool("yesslam-map", {"--map", d / "b.ysm"});
	ASSERT_EQ(info.exitCode, 0) << info.err;
	EXPECT_EQ(info.out.find("octree:       none"), std::string::npos) << info.out;
}

TEST(MapReuse, DamagedForeignAndMismatchedMapFilesAreRefusedInOneLine)
{
	TempDir d("map_reuse_bad");
	const std::string seq = walkingSequence60();
	const auto made = runTool(
		"yesslam", {"--input", seq, "--out", d / "map", "--save-map", d / "good.ysm", "--sequential", "--quiet"});
	ASSERT_EQ(made.exitCode, 0) << made.err;
	const std::string good = readText(d / "good.ysm");
	ASSERT_GT(good.size(), 1000u);

	// yesslam-map: the summary matches the map, and the exports are what they claim.
	{
		mrpt_yesslam::CSparseMap m;
		mrpt_yesslam::loadMapFile(d / "good.ysm", m, 0);
		const auto r = runTool("yesslam-map", {"--map", d / "good.ysm", "--scene", d / "m.3Dscene", "--ply",
											   d / "m.ply", "--bt", d / "m.bt", "--ot", d / "m.ot"});
		ASSERT_EQ(r.exitCode, 0) << r.err;
		// The run's semantic OctoMap went into the map file: the one written back out is the run's map.ot.
		EXPECT_NE(r.out.find("octree:       "), std::string::npos) << r.out;
		// The vocabulary fingerprint the map quotes is the one yesslam-vocab --info prints.
		const auto vocab = runTool("yesslam-vocab", {"--info", std::string(YESSLAM_SOURCE_DIR) +
																   "/share/mrpt_yesslam/vocabulary/orb_k10_L5.yvoc"});
		const auto fp = vocab.out.find("fingerprint: ");
		ASSERT_NE(fp, std::string::npos) << vocab.out;
		EXPECT_NE(r.out.find("vocabulary " + vocab.out.substr(fp + 13, 16) + ")"), std::string::npos)
			<< r.out << vocab.out;
		EXPECT_TRUE(readText(d / "m.ot") == readText(d / "map/map.ot"))
			<< "the stored octree differs from the run's map.ot";
		EXPECT_NE(r.out.find("keyframes:    " + std::to_string(m.numKeyFrames()) + " "), std::string::npos) << r.out;
		EXPECT_NE(r.out.find("map points:   " + std::to_string(m.numPoints()) + "\n"), std::string::npos) << r.out;
		EXPECT_NE(r.out.find("person ("), std::string::npos) << r.out;  // walking people were detected
		EXPECT_EQ(mrpt_yesslam::readDenseCloudPly(d / "m.ply").size(), m.numPoints());
		// Sparse points, and the header says so (it claimed a dense semantic map, every label 0).
		const std::string plyHead = readText(d / "m.ply").substr(0, 400);
		EXPECT_NE(plyHead.find("comment mrpt_yesslam sparse map points"), std::string::npos) << plyHead;
		EXPECT_EQ(plyHead.find("dense semantic map ("), std::string::npos) << plyHead;
		const auto help = runTool("yesslam-map", {"--help"});
		EXPECT_EQ(help.out.find("(required) (required)"), std::string::npos) << help.out;
		EXPECT_NE(help.out.find("[--ot OUT.ot]"), std::string::npos) << help.out;
		EXPECT_GT(fs::file_size(d / "m.3Dscene"), 1000u);
		// The saved octree's occupancy: the same occupied volume as the run's map.bt.
		auto occupiedVolume = [](const std::string& path)
		{
			octomap::OcTree t(0.1);
			EXPECT_TRUE(t.readBinary(path)) << path;
			EXPECT_DOUBLE_EQ(t.getResolution(), 0.05);
			double v = 0;
			for (auto it = t.begin_leafs(); it != t.end_leafs(); ++it)
				if (t.isNodeOccupied(*it)) v += std::pow(it.getSize(), 3);
			return v;
		};
		const double volume = occupiedVolume(d / "m.bt");
		// Issue 63 item 6: the leaves printed are the written file's (it said the in-memory tree's,
		// unknown voxels included: 65546 for a file of 28055).
		{
			octomap::OcTree t(0.1);
			ASSERT_TRUE(t.readBinary(d / "m.bt"));
			EXPECT_NE(r.out.find("(" + std::to_string(t.getNumLeafNodes()) + " leaves at"), std::string::npos) << r.out;
		}
		EXPECT_GT(volume, 0.0);
		EXPECT_NEAR(volume, occupiedVolume(d / "map/map.bt"), 1e-9);
		// A map saved without a dense map: a .bt from its points, and no .ot to give.
		const auto sparse = runTool("yesslam", {"--input", seq, "--out", d / "sparse", "--save-map", d / "sparse.ysm",
												"--sequential", "--quiet", "--no-dense-map"});
		ASSERT_EQ(sparse.exitCode, 0) << sparse.err;
		const auto r2 = runTool("yesslam-map", {"--map", d / "sparse.ysm", "--bt", d / "s.bt"});
		ASSERT_EQ(r2.exitCode, 0) << r2.err;
		EXPECT_NE(r2.out.find("octree:       none"), std::string::npos) << r2.out;
		octomap::OcTree fromPoints(0.1);
		ASSERT_TRUE(fromPoints.readBinary(d / "s.bt"));
		std::size_t occupied = 0;
		for (auto it = fromPoints.begin_leafs(); it != fromPoints.end_leafs(); ++it)
			occupied += fromPoints.isNodeOccupied(*it);
		EXPECT_GT(occupied, m.numPoints() / 10);
		const auto noOt = runTool("yesslam-map", {"--map", d / "sparse.ysm", "--ot", d / "s.ot"});
		EXPECT_EQ(noOt.exitCode, 1);
		EXPECT_NE(noOt.err.find("no semantic octree"), std::string::npos) << noOt.err;
		const auto bad = runTool("yesslam-map", {"--map", seq + "/groundtruth.txt"});
		EXPECT_EQ(bad.exitCode, 1);
		EXPECT_NE(bad.err.find("not a yesslam map"), std::string::npos) << bad.err;
	}

	auto refused = [&](const std::string& file, const std::vector<std::string>& fragments)
	{
		const auto r = runTool("yesslam", {"--input", seq, "--out", d / "x", "--load-map", file, "--quiet"});
		EXPECT_EQ(r.exitCode, 1) << r.err;
		EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
		for (const auto& f : fragments) EXPECT_NE(r.err.find(f), std::string::npos) << f << " in: " << r.err;
		EXPECT_FALSE(fs::exists(d / "x")) << "a run that cannot start leaves no output folder";
	};
	refused(d / "missing.ysm", {"missing.ysm", "cannot open"});
	writeText(d / "cut.ysm", good.substr(0, good.size() / 2));
	refused(d / "cut.ysm", {"cut.ysm", "truncated or corrupt"});
	std::string flipped = good;
	flipped[good.size() / 3] ^= 0x20;
	writeText(d / "flipped.ysm", flipped);
	refused(d / "flipped.ysm", {"flipped.ysm", "checksum"});
	refused(seq + "/groundtruth.txt", {"groundtruth.txt", "not a yesslam map"});
	writeText(d / "newer.ysm", good);
	const std::uint32_t newer = mrpt_yesslam::kMapFileVersion + 1;
	patchMapFile(d / "newer.ysm", 8, &newer, 4);
	refused(d / "newer.ysm", {"newer.ysm", "format version", "reads up to"});
	writeText(d / "vocab.ysm", good);
	const std::uint64_t other = 0x1234567812345678ull;
	patchMapFile(d / "vocab.ysm", 12, &other, 8);
	refused(d / "vocab.ysm", {"vocab.ysm", "another vocabulary"});
	// Content that passes the checksum but names a map point no keyframe has: inconsistent.
	{
		mrpt_yesslam::CSparseMap m;
		mrpt_yesslam::loadMapFile(d / "good.ysm", m, 0);
		std::ostringstream body(std::ios::binary);
		m.serialize(body);
		std::string b = std::move(body).str();
		// The last point's first observation names keyframe id 999999.
		const auto pts = m.points();
		ASSERT_FALSE(pts.empty());
		std::ostringstream last(std::ios::binary);
		pts.back().serialize(last);
		const std::string rec = std::move(last).str();
		const auto at = b.rfind(rec);
		ASSERT_NE(at, std::string::npos);
		// version(4) id(8) xyz(24) descriptor(8 + 32) colour(3) observation count(8), then the first keyframe id.
		const std::uint64_t bogus = 999999;
		std::memcpy(b.data() + at + 4 + 8 + 24 + 8 + 32 + 3 + 8, &bogus, 8);
		std::string file = good.substr(0, 20) + b + std::string(16, '\0');  // no octree section
		const std::uint64_t sum = mrpt_yesslam::binio::checksum(file.data(), file.size());
		file.append(reinterpret_cast<const char*>(&sum), 8);
		writeText(d / "inconsistent.ysm", file);
	}
	refused(d / "inconsistent.ysm", {"inconsistent.ysm", "inconsistent"});
	// Localisation only without a map, and a map path that cannot be written, fail before the run.
	auto fails = [&](const std::vector<std::string>& args, const std::string& fragment)
	{
		const auto r = runTool("yesslam", args);
		EXPECT_EQ(r.exitCode, 1) << r.err;
		EXPECT_NE(r.err.find(fragment), std::string::npos) << r.err;
	};
	fails({"--input", seq, "--out", d / "y", "--localize-only"}, "--load-map");
	fails({"--input", "openni2", "--out", d / "y", "--skip-frames", "5"}, "recorded input");
	// A new folder is made (Grid2D.YesslamMapMakesTheGridFromASavedMapOrAnOctoMap saves into one); one
	// under a file cannot be.
	fails({"--input", seq, "--out", d / "y", "--save-map", d / "good.ysm/dir/m.ysm"}, "its folder cannot be made");
}
