// yesslam-oni: converts a rawlog or TUM RGB-D folder into an OpenNI2 recording (.oni).
#include <cstdio>

#include "mrpt_yesslam/io/COniWriter.h"
#include "mrpt_yesslam/util/CommandLine.h"
#include "mrpt_yesslam/util/Error.h"
#include "mrpt_yesslam/util/ProgressBar.h"

using namespace mrpt_yesslam;

int main(int argc, char** argv)
{
	return runTool(
		"yesslam-oni",
		[&]() -> int
		{
			std::string input, output;
			CInputSource::TOptions in;
			std::size_t maxFrames = 0;
			bool quiet = false;
			CommandLine cl(
				"yesslam-oni", "yesslam-oni --input PATH --output OUT.oni [options]",
				"Writes RGB-D frames (a .rawlog or a TUM RGB-D folder) as an OpenNI2 recording that OpenNI2's own\n"
				"file driver plays, as a camera would deliver them: `yesslam --input openni2:OUT.oni` runs the live\n"
				"path (OpenNI2, capture thread, frame dropping) on recorded data, and any OpenNI2 program can read "
				"it.\n"
				"Frames keep their times (microseconds since the Unix epoch), so the input's ground truth (copied to\n"
				"OUT_groundtruth.txt) and its detections.txt (copied beside OUT.oni, never over a different one) still "
				"match. Depth and colour are stored\n"
				"uncompressed (about 1.5 MB a 640x480 frame); depth in 100 um units when the input's units convert\n"
				"exactly (TUM's do), else millimetres.",
				{"yesslam-oni --input rgbd_dataset_freiburg3_walking_xyz --output walking_xyz.oni",
				 "yesslam-oni --input walking.rawlog --output walking.oni --max-frames 300"});
			cl.text("input", "PATH", ".rawlog or TUM RGB-D folder", &input, true);
			cl.text("output", "FILE", ".oni file to write (atomically; its folder is created)", &output, true);
			cl.text("camera", "NAME|FILE", "TUM folders: fr1, fr2, fr3 or a camera file (as yesslam --camera)",
					&in.camera);
			cl.count("max-frames", "N", "convert at most N frames (0 = all)", &maxFrames);
			cl.flag("quiet", "no progress bar", &quiet);
			if (!cl.parse(argc, argv)) return 0;
			installInterruptHandler();
			ProgressBar bar("yesslam-oni", 0, !quiet);
			const TOniConversion r = convertToOni(
				input, output, in, maxFrames,
				[&](std::size_t done, std::size_t total)
				{
					bar.setTotal(total);
					bar.update(done);
				},
				[] { return interruptRequested(); });
			bar.finish();
			std::printf("output:       %s\n", output.c_str());
			std::printf("frames:       %zu\n", r.frames);
			std::printf("span:         %.3f s (%.6f .. %.6f)\n", r.tLast - r.tFirst, r.tFirst, r.tLast);
			std::printf("depth unit:   %s\n", r.depthIn100um ? "100 um (exact)" : "1 mm");
			if (r.clippedPixels)
				std::printf("clipped:      %zu depth pixels beyond the 16-bit range stored as 0\n", r.clippedPixels);
			std::printf("size:         %.2f MiB\n", static_cast<double>(r.bytes) / (1024.0 * 1024.0));
			std::printf("ground truth: %s\n",
						r.groundTruth.empty() ? "(none found beside the input)" : r.groundTruth.c_str());
			std::printf("camera file: %s\n", r.cameraFile.empty() ? "(none: no frame written)" : r.cameraFile.c_str());
			std::printf("detections:   %s\n", !r.detections.empty() ? r.detections.c_str() : "(none beside the input)");
			if (!r.detectionsNote.empty()) std::fprintf(stderr, "yesslam-oni: warning: %s\n", r.detectionsNote.c_str());
			if (r.interrupted)
			{
				std::fprintf(stderr, "yesslam-oni: interrupted; the recording holds the %zu frames converted so far\n",
							 r.frames);
				return interruptExitCode();
			}
			return 0;
		});
}
