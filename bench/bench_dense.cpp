// Dense semantic map against a yesslam-sim sequence's exact labels: ghost voxels where people
// walked, label accuracy of occupied voxels, the 2D grid's cells, file sizes, dense-stage time and
// tracking fps.
// Usage: bench_dense SIM_DIR OUT_DIR [--no-dynamic-filter] [--no-dense-map] [--sequential] [--config FILE]
// Prints one line of key=value pairs (bench/bench_dense.sh collects them into a table).
#include <cstdio>
#include <cstring>
#include <string>

#include "mrpt_yesslam/dense/DenseMapExport.h"
#include "mrpt_yesslam/eval/SemanticMapScoring.h"
#include "mrpt_yesslam/io/Trajectory.h"
#include "mrpt_yesslam/jobs/SlamJob.h"
#include "mrpt_yesslam/mapio/GridMapFiles.h"

using namespace mrpt_yesslam;

int main(int argc, char** argv)
{
	if (argc < 3)
	{
		std::fprintf(stderr,
					 "usage: bench_dense SIM_DIR OUT_DIR [--no-dynamic-filter] [--no-dense-map] [--sequential] "
					 "[--config FILE]\n");
		return 2;
	}
	try
	{
		TSlamJobOptions o;
		o.input = argv[1];
		o.outDir = argv[2];
		o.slam.detector.backend = "auto";
		for (int i = 3; i < argc; i++)
		{
			if (!std::strcmp(argv[i], "--no-dynamic-filter")) o.slam.system.dynamicFilter = false;
			if (!std::strcmp(argv[i], "--sequential")) o.slam.system.parallel = false;
			if (!std::strcmp(argv[i], "--no-dense-map")) o.slam.dense.enabled = false;
			if (!std::strcmp(argv[i], "--config") && i + 1 < argc) o.slam.loadFromFile(argv[++i]);
		}
		const TSlamJobSummary s = runSlamJob(o);
		if (!o.slam.dense.enabled)
		{
			// Only the tracking figures: the run the dense stage's cost is measured against.
			std::printf("ate_mm=%.1f fps=%.1f\n", s.evaluated ? 1000 * s.eval.ate.stats.rmse : -1.0,
						s.seconds > 0 ? s.stats.frames / s.seconds : 0.0);
			return 0;
		}
		const auto tree = CSemanticOcTree::readFile(o.outDir + "/map.ot");
		const TTrajectory kfs = readTumTrajectory(o.outDir + "/keyframes.txt");
		const TTrajectory gt = readTumTrajectory(std::string(argv[1]) + "/groundtruth.txt");
		// The map's frame in the ground truth's: the first keyframe's true pose times its estimate's inverse.
		const TStampedPose* g0 = nullptr;
		for (const auto& g : gt)
			if (!g0 || std::abs(g.t - kfs.front().t) < std::abs(g0->t - kfs.front().t)) g0 = &g;
		const mrpt::poses::CPose3D mapInGt = g0->asPose() + (-kfs.front().asPose());
		const TSemanticMapScore sc = scoreSemanticMap(*tree, argv[1], mapInGt);
		// The 2D grid as a navigation stack reads it (issue 67), its band as the run measured it.
		TOccupancyGrid2D grid = readRosMap(o.outDir + "/map_2d.yaml");
		grid.minZ = o.slam.grid.minHeight, grid.maxZ = o.slam.grid.maxHeight;
		const TGridScore gs = scoreGrid2D(grid, argv[1], mapInGt);
		const auto& st = s.stats.stageMs;
		auto median = [&](const char* k)
		{
			auto it = st.find(k);
			if (it == st.end() || it->second.empty()) return 0.0;
			auto v = it->second;
			std::nth_element(v.begin(), v.begin() + v.size() / 2, v.end());
			return v[v.size() / 2];
		};
		std::printf(
			"ate_mm=%.1f fps=%.1f dense_ms=%.1f build_s=%.2f points=%zu occupied=%zu swept=%zu ghost=%zu "
			"ghost_share=%.4f "
			"label_acc=%.3f object_recall=%.3f object_precision=%.3f ply_mb=%.2f ot_mb=%.2f bt_mb=%.3f "
			"grid_path_free=%.3f grid_static_occupied=%.3f grid_swept_occupied=%.4f grid_swept_cells=%zu\n",
			s.evaluated ? 1000 * s.eval.ate.stats.rmse : -1.0, s.seconds > 0 ? s.stats.frames / s.seconds : 0.0,
			median("dense"), s.dense.buildMs / 1000, s.dense.cloudPoints, s.dense.occupiedLeaves, sc.sweptVoxels,
			sc.ghostVoxels, sc.ghostShare(), sc.labelAccuracy(), sc.objectRecall(), sc.objectPrecision(),
			s.dense.plyBytes / 1e6, s.dense.otBytes / 1e6, s.dense.btBytes / 1e6, gs.pathFreeShare(),
			gs.staticOccupiedShare(), gs.sweptOccupiedShare(), gs.sweptCells);
		for (const auto& [label, cnt] : sc.perLabel)
			std::printf("  label %d: %zu / %zu correct\n", label, cnt.first, cnt.second);
		return 0;
	}
	catch (const std::exception& e)
	{
		std::fprintf(stderr, "bench_dense: %s\n", e.what());
		return 1;
	}
}
