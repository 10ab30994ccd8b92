// yesslam-sim: synthetic dynamic RGB-D sequences with full ground truth (poses, labels, boxes,
// simulated detections), written as a TUM folder, an MRPT rawlog and a .3Dscene.
#include <cstdio>

#include "mrpt_yesslam/sim/CSequenceSimulator.h"
#include "mrpt_yesslam/util/CommandLine.h"
#include "mrpt_yesslam/util/Error.h"
#include "mrpt_yesslam/util/ProgressBar.h"

using namespace mrpt_yesslam;

int main(int argc, char** argv)
{
	return runTool(
		"yesslam-sim",
		[&]() -> int
		{
			TSimOptions o;
			std::size_t seed = o.seed, frames = 0, roomSeed = 0;
			double people = -1;
			bool list = false, modelHash = false, noNoise = false, noRawlog = false, quiet = false, verbose = false;
			CommandLine cl(
				"yesslam-sim",
				"yesslam-sim --preset NAME --out DIR [--seed S] [--frames N] [--people K] [--trajectory FILE] "
				"[--textures DIR] [--det-noise none|yolo] [--no-noise] [--list-presets]",
				"Renders a dynamic office (6 x 5 x 3 m, COCO furniture, walking or sitting people) as a TUM fr3-like\n"
				"RGB-D sequence at 640x480, 30 Hz, with exact ground truth. DIR receives: rgb/, depth/ (16-bit PNG,\n"
				"value/5000 = m), rgb.txt, depth.txt, associations.txt, groundtruth.txt, calibration.txt, "
				"labels/class/\n"
				"(COCO id + 1) and labels/instance/ PNGs, objects.txt (per frame: instance, class, visible pixels and\n"
				"fraction, box, moving), detections.txt (simulated detector), sequence.rawlog (+ "
				"sequence_groundtruth.txt),\n"
				"scene.3Dscene (the static room) and meta.json. The same arguments give byte-identical files.",
				{"yesslam-sim --preset walking_xyz --out sim/walking_xyz --frames 300",
				 "yesslam-sim --preset walking_xyz --out sim/wxyz_real --trajectory "
				 "../shared/data/tum_eval_trajectories/fr3_walking_xyz_groundtruth.txt",
				 "yesslam-sim --list-presets"});
			cl.text("preset", "NAME", "scenario (see --list-presets)", &o.preset);
			cl.text("out", "DIR", "output folder (created if missing)", &o.outDir);
			cl.count("seed", "S", "seed of the room layout, textures and noise", &seed);
			cl.count("room-seed", "R",
					 "the room (layout, furniture, textures) from R instead of --seed, and the people start elsewhere "
					 "on their paths: "
					 "passes with the same R and different seeds are the same room in the same world frame (map reuse)",
					 &roomSeed);
			cl.count("frames", "N", "number of frames (0 = the preset's)", &frames);
			cl.number("people", "K", "number of people (-1 = the preset's)", &people);
			cl.text("trajectory", "FILE",
					"replay a TUM trajectory at its own stamps, placed in the room, instead of the preset's motion",
					&o.trajectoryFile);
			cl.text("textures", "DIR", "use the photos in DIR (.png/.jpg) as textures instead of procedural clutter",
					&o.texturesDir);
			cl.text("det-noise", "none|yolo",
					"simulated detector: exact boxes, or misses, jitter and false positives like YOLO", &o.detNoise);
			cl.flag("no-noise", "no sensor noise (exact depth and colour)", &noNoise);
			cl.flag("motion-blur", "blur colour images along the camera motion", &o.motionBlur);
			cl.flag("auto-exposure", "vary image brightness slowly, like auto exposure", &o.autoExposure);
			cl.flag("real-sensor",
					"the sensor as measured on real Xtion/Kinect frames (bench/bench_realism.sh): depth error smooth "
					"over tens of pixels, depth lost in blobs (silhouettes, some dark surfaces) and in the "
					"registration border, soft colour images, motion blur, auto exposure",
					&o.realSensor);
			cl.number(
				"depth-offset", "MS",
				"take each depth image up to MS milliseconds before or after its colour image, the offset drifting "
				"through that range and back every 15 s (0.15 ms a frame at 16.7, as between two free-running 30 Hz "
				"streams) (depth.txt gets the depth's own stamps; the real Bonn frames: 16.7); at most half a frame "
				"(16.7 at 30 Hz; a replayed trajectory's median interval: beyond it a depth image is nearer the next "
				"colour image and is paired with it); -1 = the preset's: 16.7 for crowd (the double of those frames; "
				"held to half a frame on a faster replayed trajectory), else 0",
				&o.depthOffsetMs);
			cl.number("readout", "MS",
					  "rolling shutter: read the rows of the colour and depth images top to bottom over MS "
					  "milliseconds, each from the camera's pose and the people's positions at its moment (the stamp "
					  "is the middle row's); 0 = global shutter (default: 28 with --real-sensor, as Kinect and Xtion, "
					  "else 0); written to calibration.txt and meta.json",
					  &o.readoutMs);
			cl.number("speed", "F",
					  "the preset's camera moves F times faster (0.1..10; the path is the same, frames stay 30 Hz)",
					  &o.speed);
			cl.flag("moving-chair", "also push a chair across the room (a dynamic object that is not a person)",
					&o.movingChair);
			cl.count("undetected-people", "K",
					 "K of the moving people never appear in detections.txt (movers the detector never reports)",
					 &o.undetectedPeople);
			cl.number("miss-rate", "P", "also drop each detection of a moving object with probability P (0..1)",
					  &o.missRate);
			cl.flag("no-rawlog", "do not write sequence.rawlog", &noRawlog);
			cl.flag("overlays", "also write labels/overlay/: colour images with labels tinted and object boxes drawn",
					&o.overlays);
			cl.flag("list-presets", "print the presets and exit", &list);
			cl.flag(
				"model-hash",
				"print the version of the simulator's model (a hash of its sources; meta.json's \"model\") and exit",
				&modelHash);
			cl.flag("quiet", "no progress bar", &quiet);
			cl.flag("verbose", "also print the time per frame of each stage (rendering, labels, noise, encoding, ...)",
					&verbose);
			if (!cl.parse(argc, argv)) return 0;
			if (modelHash)
			{
				std::printf("%s\n", simulatorModelHash().c_str());
				return 0;
			}
			if (list)
			{
				for (const auto& p : simPresets())
					std::printf("%-20s %4zu frames  %s\n", p.name.c_str(), p.frames, p.description.c_str());
				return 0;
			}
			if (o.outDir.empty()) throw InputError("", "missing required option --out (see --help)");
			if (quiet && verbose) throw InputError("", "--quiet and --verbose contradict each other: give one");
			if (seed > 0xffffffffu) throw InputError("", "--seed must fit in 32 bits");
			if (roomSeed > 0xffffffffu) throw InputError("", "--room-seed must fit in 32 bits");
			o.roomSeed = static_cast<uint32_t>(roomSeed);
			if (!(people >= -1 && people <= 20 && people == static_cast<int>(people)))
				throw InputError("", "--people must be an integer -1..20 (-1: the preset's own number)");
			o.seed = static_cast<uint32_t>(seed);
			o.frames = frames;
			o.people = static_cast<int>(people);
			o.noise = !noNoise;
			o.writeRawlog = !noRawlog;
			for (int i = 0; i < argc; i++) o.commandLine += (i ? " " : "") + std::string(argv[i]);

			installInterruptHandler();
			ProgressBar bar("yesslam-sim", 0, !quiet);
			const auto s = runSimulation(
				o,
				[&](std::size_t done, std::size_t total)
				{
					bar.setTotal(total);
					bar.update(done);
				},
				[] { return interruptRequested(); });
			bar.finish();
			std::printf("frames:             %zu\n", s.frames);
			std::printf("dynamic pixels:     %.1f %% mean, %.1f %% max\n", 100 * s.meanDynamicShare,
						100 * s.maxDynamicShare);
			std::printf("detections:         %zu\n", s.detections);
			std::printf("time:               %.1f s (%.1f frames/s)\n", s.seconds,
						s.seconds > 0 ? s.frames / s.seconds : 0.0);
			if (verbose)
				for (const auto& [stage, sec] : s.stageSeconds)
					std::printf("  %-24s %7.1f ms/frame\n", stage.c_str(), s.frames ? 1000 * sec / s.frames : 0.0);
			std::printf("output:             %s (TUM folder; %sscene.3Dscene, meta.json)\n", o.outDir.c_str(),
						o.writeRawlog ? "sequence.rawlog, " : "");
			if (s.interrupted)
			{
				std::fprintf(stderr, "yesslam-sim: interrupted; %s holds the first %zu frames\n", o.outDir.c_str(),
							 s.frames);
				return interruptExitCode();
			}
			return 0;
		});
}
