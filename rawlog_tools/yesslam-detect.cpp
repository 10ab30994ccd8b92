// yesslam-detect: runs a detector (and the dynamic-object masker where there is depth) over an
// image, a TUM folder or a rawlog, so detections can be computed once, reused and checked.
#include <cstdio>

#include "mrpt_yesslam/jobs/DetectionJob.h"
#include "mrpt_yesslam/util/CommandLine.h"
#include "mrpt_yesslam/util/ConfigFile.h"
#include "mrpt_yesslam/util/Error.h"
#include "mrpt_yesslam/util/ProgressBar.h"

using namespace mrpt_yesslam;

int main(int argc, char** argv)
{
	return runTool(
		"yesslam-detect",
		[&]() -> int
		{
			TDetectJobOptions o;
			std::string configPath;
			double conf = o.detector.confThreshold;
			std::size_t inputSize = 0;
			bool quiet = false;
			CommandLine cl(
				"yesslam-detect",
				"yesslam-detect [--model MODEL(.cfg|.onnx) [--weights FILE.weights] --names NAMES.txt] [--conf 0.6] "
				"[--dynamic person,...] --input PATH --out DIR [--overlay]",
				"Runs a YOLO-family detector through OpenCV DNN on the CPU (Darknet cfg+weights, or ONNX exports of\n"
				"YOLOv5/v7/v8 and YOLOX; the layout is recognised from the output shape) over an image, a TUM folder\n"
				"or a rawlog. Writes DIR/detections.txt ('timestamp class_id score x y w h instance_id', pixels;\n"
				"timestamp 0 for a single image), DIR/masks/<stamp>.png (the dynamic-object masks, for inputs with\n"
				"depth) and with --overlay DIR/overlays/<stamp>.png. The detections file is what the SLAM app's\n"
				"'file' detector backend reads. Without --model it runs the shipped Yolo-Fastest-1.1 (COCO), as "
				"yesslam does.",
				{"yesslam-detect --input photo.jpg --out det --overlay   (the shipped Yolo-Fastest)",
				 "yesslam-detect --model yolo-fastest-1.1-xl.cfg --weights yolo-fastest-1.1-xl.weights --names "
				 "coco.names "
				 "--input rgbd_dataset_freiburg3_walking_xyz --out det --overlay",
				 "yesslam-detect --model yolov7-tiny.onnx --names coco.names --input photo.jpg --out det --overlay"});
			cl.text("model", "FILE",
					"network: darknet .cfg (with --weights) or .onnx (default: the shipped Yolo-Fastest-1.1)",
					&o.detector.model);
			cl.text("weights", "FILE", "darknet weights", &o.detector.weights);
			cl.text("names", "FILE", "class names, one per line, in the model's order (needed with --model)",
					&o.detector.names);
			cl.number("conf", "P", "drop detections below this confidence (the paper: 0.6)", &conf);
			cl.text("dynamic", "NAMES", "comma-separated classes treated as dynamic and masked",
					&o.detector.dynamicClasses);
			std::string formats;
			for (const auto& f : yoloOutputFormats()) formats += (formats.empty() ? "" : ", ") + f;
			cl.text("format", "F", "output layout: " + formats, &o.detector.format);
			cl.count("input-size", "PX", "network input side (0 = from the model)", &inputSize);
			cl.text("mask-method", "M", "masking: edge_fill (paper), fill, box", &o.masker.method);
			cl.text("input", "PATH", "image file, TUM RGB-D folder or .rawlog", &o.input, true);
			cl.text("out", "DIR", "output folder (created if missing)", &o.outDir, true);
			cl.flag("overlay", "also write images with boxes, names, scores and masks drawn", &o.overlay);
			cl.text("camera", "NAME|FILE", "TUM folders: fr1, fr2, fr3 or a camera file", &o.source.camera);
			cl.count("max-frames", "N", "process at most N frames (0 = all)", &o.maxFrames);
			cl.text("config", "FILE", "INI/YAML config with [Detector], [DynamicMask], [Input]; options given here win",
					&configPath);
			cl.flag("quiet", "no progress bar", &quiet);
			if (!cl.parse(argc, argv)) return 0;
			if (cl.given("model") && !cl.given("names") && configPath.empty())
				throw InputError("", "--names is needed with --model (the class names in the model's order)");
			if (!configPath.empty())
			{
				const TDetectJobOptions cli = o;
				loadOptionsFromFile(configPath, "Detector", o.detector, CObjectDetector::TOptions::configKeys());
				loadOptionsFromFile(configPath, "DynamicMask", o.masker, CDynamicObjectMasker::TOptions::configKeys());
				loadOptionsFromFile(configPath, "Input", o.source, CInputSource::TOptions::configKeys());
				o.detector.model = cli.detector.model;
				o.detector.names = cli.detector.names;
				if (cl.given("weights")) o.detector.weights = cli.detector.weights;
				if (cl.given("dynamic")) o.detector.dynamicClasses = cli.detector.dynamicClasses;
				if (cl.given("format")) o.detector.format = cli.detector.format;
				if (cl.given("mask-method")) o.masker.method = cli.masker.method;
				if (cl.given("camera")) o.source.camera = cli.source.camera;
			}
			o.detector.backend = "yolo";
			if (cl.given("conf") || configPath.empty()) o.detector.confThreshold = conf;
			if (cl.given("input-size")) o.detector.inputSize = static_cast<int>(inputSize);

			installInterruptHandler();
			ProgressBar bar("yesslam-detect", 0, !quiet);
			const auto sum = runDetectionJob(
				o,
				[&](std::size_t done, std::size_t total)
				{
					bar.setTotal(total);
					bar.update(done);
				},
				[] { return interruptRequested(); });
			bar.finish();
			std::printf("frames:          %zu\n", sum.frames);
			std::printf("detections:      %zu (%zu dynamic)\n", sum.detections, sum.dynamicDetections);
			std::printf("detect ms/frame: %.1f (median)\n", sum.detectMsMedian);
			if (sum.masks) std::printf("mask ms/frame:   %.2f (median)\n", sum.maskMsMedian);
			std::printf("detections file: %s\n", sum.detectionsFile.c_str());
			if (sum.masks) std::printf("masks:           %s/masks/\n", o.outDir.c_str());
			if (o.overlay) std::printf("overlays:        %s/overlays/\n", o.outDir.c_str());
			if (sum.interrupted)
			{
				std::fprintf(stderr, "yesslam-detect: interrupted; results cover the first %zu frames\n", sum.frames);
				return interruptExitCode();
			}
			return 0;
		});
}
