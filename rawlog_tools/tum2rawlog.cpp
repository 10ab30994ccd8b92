// tum2rawlog: converts a TUM RGB-D folder into an MRPT rawlog with exact 16-bit depth.
#include <cstdio>

#include "mrpt_yesslam/io/TumToRawlog.h"
#include "mrpt_yesslam/util/CommandLine.h"
#include "mrpt_yesslam/util/ConfigFile.h"
#include "mrpt_yesslam/util/Error.h"
#include "mrpt_yesslam/util/ProgressBar.h"

using namespace mrpt_yesslam;

int main(int argc, char** argv)
{
	return runTool(
		"tum2rawlog",
		[&]() -> int
		{
			TTumToRawlogOptions o;
			bool quiet = false;
			std::string configPath;
			CommandLine cl(
				"tum2rawlog", "tum2rawlog --input TUM_FOLDER --output OUT.rawlog [options]",
				"Converts a TUM RGB-D folder (rgb.txt, depth.txt, rgb/, depth/) into an MRPT rawlog of\n"
				"CObservation3DRangeScan frames. rgb and depth are paired as the benchmark's associate.py\n"
				"pairs them; 16-bit depth values are copied unchanged (rangeUnits = 1/depth_scale, 0.0002 m\n"
				"for TUM). groundtruth.txt, if present, is copied to OUT_groundtruth.txt.",
				{"tum2rawlog --input rgbd_dataset_freiburg3_walking_xyz --output walking_xyz.rawlog",
				 "tum2rawlog --input seq --output seq.rawlog --camera fr1 --external-images"});
			cl.text("input", "DIR", "TUM RGB-D folder to read", &o.folder, true);
			cl.text("output", "FILE", "rawlog to write (written atomically)", &o.output, true);
			cl.text("camera", "NAME|FILE",
					"fr1, fr2, fr3 (TUM calibrations) or a camera file 'fx fy cx cy [w h [depth_scale]]' + "
					"optional 'k1 k2 p1 p2 k3' line; default: calibration.txt in the folder, else the freiburg "
					"name in the folder path",
					&o.input.camera);
			cl.number("max-diff", "SECONDS", "largest rgb/depth stamp difference for a pair", &o.input.maxDiff);
			cl.flag("external-images", "store colour images as PNG files in OUT_Images/ instead of inline",
					&o.externalImages);
			cl.count("max-frames", "N", "convert at most N frames (0 = all)", &o.maxFrames);
			cl.text("config", "FILE", "INI or YAML config; its [Input] section sets camera, maxDiff, sensorLabel",
					&configPath);
			cl.flag("quiet", "no progress bar", &quiet);
			if (!cl.parse(argc, argv)) return 0;
			if (!configPath.empty())
			{
				// The file gives the defaults; options given on the command line win.
				const auto cli = o.input;
				loadOptionsFromFile(configPath, "Input", o.input, CInputSource::TOptions::configKeys());
				if (cl.given("camera")) o.input.camera = cli.camera;
				if (cl.given("max-diff")) o.input.maxDiff = cli.maxDiff;
			}

			installInterruptHandler();
			ProgressBar bar("tum2rawlog", 0, !quiet);
			const auto sum = convertTumToRawlog(
				o,
				[&](std::size_t done, std::size_t total)
				{
					bar.setTotal(total);
					bar.update(done);
				},
				[] { return interruptRequested(); });
			bar.finish();
			std::printf("input:        %s\n", o.folder.c_str());
			std::printf("output:       %s\n", o.output.c_str());
			std::printf("camera:       %s\n", sum.camera.c_str());
			std::printf("frames:       %zu\n", sum.frames);
			std::printf("skipped:      %zu (rgb images without a depth image within %g s)\n", sum.skipped,
						o.input.maxDiff);
			std::printf("span:         %.3f s (%.6f .. %.6f)\n", sum.tLast - sum.tFirst, sum.tFirst, sum.tLast);
			std::printf("size:         %.2f MiB\n", static_cast<double>(sum.bytes) / (1024.0 * 1024.0));
			if (!sum.imagesDir.empty()) std::printf("images:       %s\n", sum.imagesDir.c_str());
			std::printf("ground truth: %s\n",
						sum.groundTruth.empty() ? "(none in the folder)" : sum.groundTruth.c_str());
			std::printf("camera file: %s\n", sum.cameraFile.c_str());
			if (sum.interrupted)
			{
				std::fprintf(stderr, "tum2rawlog: interrupted; the rawlog holds the %zu frames converted so far\n",
							 sum.frames);
				return interruptExitCode();
			}
			return 0;
		});
}
