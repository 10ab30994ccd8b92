// yesslam-cloud: places the RGB-D frames of a rawlog or TUM folder at given poses (ground truth, or
// a trajectory from yesslam) and writes the coloured point cloud + camera path as a .3Dscene.
#include <cstdio>

#include "mrpt_yesslam/io/CInputSource.h"
#include "mrpt_yesslam/io/SceneExport.h"
#include "mrpt_yesslam/util/CommandLine.h"
#include "mrpt_yesslam/util/ConfigFile.h"
#include "mrpt_yesslam/util/Error.h"
#include "mrpt_yesslam/util/ProgressBar.h"

using namespace mrpt_yesslam;

int main(int argc, char** argv)
{
	return runTool(
		"yesslam-cloud",
		[&]() -> int
		{
			std::string input, posesPath, out;
			CInputSource::TOptions in;
			TSceneExportOptions o;
			std::size_t stride = 4, step = 1;
			bool quiet = false;
			std::string configPath;
			CommandLine cl(
				"yesslam-cloud", "yesslam-cloud --input PATH --poses TRAJ.txt --out SCENE.3Dscene [options]",
				"Back-projects every frame of a rawlog or TUM folder with the pose of the nearest stamp in a\n"
				"TUM trajectory (camera-to-world, z forward) and writes one coloured point cloud, the camera path\n"
				"and camera axes as an MRPT .3Dscene (view it with SceneViewer3D or yesslam-render). With ground\n"
				"truth as poses, a sharp cloud confirms that data, camera model and poses agree.",
				{"yesslam-cloud --input rgbd_dataset_freiburg1_desk --poses "
				 "rgbd_dataset_freiburg1_desk/groundtruth.txt "
				 "--out desk.3Dscene"});
			cl.text("input", "PATH", "rawlog file or TUM RGB-D folder", &input, true);
			cl.text("poses", "FILE", "TUM trajectory giving each frame's camera pose", &posesPath, true);
			cl.text("out", "FILE", ".3Dscene to write (atomically)", &out, true);
			cl.text("camera", "NAME|FILE", "TUM folders: fr1, fr2, fr3 or a camera file (see tum2rawlog --help)",
					&in.camera);
			cl.count("stride", "PX", "use every n-th pixel in x and y", &stride);
			cl.count("frame-step", "N", "use every n-th frame", &step);
			cl.count("max-frames", "N", "use at most N frames (0 = all)", &o.maxFrames);
			cl.number("max-depth", "M", "ignore depth beyond this distance", &o.maxDepth);
			cl.number("max-diff", "SECONDS", "a frame needs a pose this close in time", &o.maxTimeDiff);
			cl.text("config", "FILE", "INI or YAML config; its [Input] section sets camera, maxDiff, sensorLabel",
					&configPath);
			cl.flag("quiet", "no progress bar", &quiet);
			if (!cl.parse(argc, argv)) return 0;
			if (!configPath.empty())
			{
				// The file gives the defaults; options given on the command line win.
				const auto cli = in;
				loadOptionsFromFile(configPath, "Input", in, CInputSource::TOptions::configKeys());
				if (cl.given("camera")) in.camera = cli.camera;
			}
			if (stride < 1 || step < 1) throw InputError("", "--stride and --frame-step must be at least 1");
			if (!(o.maxDepth > 0)) throw InputError("", "--max-depth must be positive (metres)");
			o.pixelStride = static_cast<int>(stride);
			o.frameStep = step;

			const TTrajectory poses = readTumTrajectory(posesPath);
			if (poses.empty()) throw InputError(posesPath, "contains no poses");
			auto src = openInputSource(input, in);
			// The frames this run reads: the input's, at most --max-frames.
			std::size_t total = src->sizeHint();
			if (o.maxFrames && (total == 0 || total > o.maxFrames)) total = o.maxFrames;
			ProgressBar bar("yesslam-cloud", total, !quiet);
			TSceneExportSummary sum;
			auto scene = buildPosedCloudScene(*src, poses, o, sum, [&](std::size_t n) { bar.update(n); });
			bar.finish();
			saveSceneAtomically(*scene, out);
			std::printf("frames used:         %zu\n", sum.framesUsed);
			std::printf("frames without pose: %zu\n", sum.framesWithoutPose);
			std::printf("points:              %zu\n", sum.points);
			std::printf("scene:               %s\n", out.c_str());
			return 0;
		});
}
