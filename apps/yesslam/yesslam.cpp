// yesslam: RGB-D SLAM for dynamic scenes (YES-SLAM) over a rawlog, a TUM RGB-D folder or a live
// OpenNI2 camera.
#include <cmath>
#include <cstdio>
#include <map>
#include <tuple>

#include "mrpt_yesslam/io/COpenNI2Source.h"
#include "mrpt_yesslam/jobs/SlamJob.h"
#include "mrpt_yesslam/util/CommandLine.h"
#include "mrpt_yesslam/util/Error.h"
#include "mrpt_yesslam/util/ProgressBar.h"
#include "mrpt_yesslam/util/TextParsing.h"

using namespace mrpt_yesslam;

int main(int argc, char** argv)
{
	return runTool(
		"yesslam",
		[&]() -> int
		{
			TSlamJobOptions o;
			std::string config, detector = "auto", policy, camera, worldFrame, gtFormat = "auto";
			bool noDynamic = false, noLoop = false, noDense = false, sequential = false, quiet = false,
				 listDevices = false, localizeOnly = false;
			double octomapRes = 0.05, width = 640, height = 480, fps = 30, speed = 1;
			CommandLine cl(
				"yesslam",
				"yesslam --input PATH [--config CFG.ini] --out OUTDIR [--detector auto|yolo|file|hog|none] "
				"[--no-dynamic-filter] [--max-frames N] [--gt GT.txt [--gt-format auto|tum|bonn]]",
				"RGB-D SLAM for scenes with moving people (the YES-SLAM method): detects people, cuts them out of\n"
				"the depth image with an edge-enhanced flood fill, tracks ORB features of the static scene only,\n"
				"selects keyframes semantically, refines a local map with bundle adjustment (Ceres) and closes loops\n"
				"(bag of words with the shipped vocabulary + semantic similarity, pose graph, global BA).\n"
				"PATH is a .rawlog (CObservation3DRangeScan frames), a TUM RGB-D folder (rgb.txt, depth.txt), or\n"
				"openni2[:URI] for a live OpenNI2 camera (Kinect, Xtion, Astra; the first one without a URI; see\n"
				"--list-devices) or an .oni recording played through OpenNI2. Live frames are captured on their own\n"
				"thread; when SLAM falls behind the oldest waiting frame is dropped (counted in stats.json and the\n"
				"status line: capture fps, processed fps, dropped frames, tracking state). --record keeps every "
				"frame.\n"
				"Every output is in a z-up world frame (x forward, y left, z up; levelled by the floor, which is at z "
				"= 0,\n"
				"when one is seen; the file headers state it and T_world_map), or with --world-frame optical in the "
				"first\n"
				"keyframe's camera frame. OUTDIR receives trajectory.txt (TUM format, a pose for every frame that has "
				"one: the pose\n"
				"tracking measured against its reference keyframe, carried by that keyframe's final pose, as ORB-SLAM2 "
				"saves it),\n"
				"trajectory_online.txt (each frame's pose as the run had it then, what a robot had; its ATE is printed "
				"as\n"
				"online_ate_rmse), trajectory_smoothed.txt (trajectory.txt smoothed after the run over up to 8 LATER "
				"frames\n"
				"too, lost frames filled in: [Output]; smoothed_ate_rmse), keyframes.txt, map.3Dscene\n"
				"(map points, keyframes, trajectory; open with SceneViewer3D or yesslam-render), stats.json\n"
				"(frames, tracking rate, keyframes, loops, per-stage median and p95 ms), frames.csv (per frame: "
				"tracking\n"
				"state, inliers, map size, stage times, and where its pose comes from: tracked, coasted, interpolated, "
				"none), config_used.ini,\n"
				"loop_candidates.csv (with loop closing: every loop candidate and the stage it stopped at; "
				"yesslam-eval --loops\n"
				"labels them by a ground truth), and with ground\n"
				"truth (--gt, or groundtruth.txt found beside the input) eval.json, eval_online.json and "
				"eval_smoothed.json;\n"
				"ATE and RPE are printed.\n"
				"The dense semantic map (unless --no-dense-map): dense_cloud.ply (colour, fused class label and its\n"
				"probability per point), map.ot (semantic OctoMap: occupancy, colour, label) and map.bt (occupancy "
				"only,\n"
				"for octovis and navigation stacks); map.3Dscene then also holds the octree coloured by label. People\n"
				"are left out, and the space they walked through is free. A 2D occupancy grid for navigation is\n"
				"projected from the octree's band [Grid2D] minHeight-maxHeight (0.15-1.5 m) above the floor, people\n"
				"never occupied: map_2d.gridmap (MRPT COccupancyGridMap2D), map_2d.pgm + map_2d.yaml (ROS\n"
				"map_server) and map_2d.png (with the path).\n"
				"--save-map keeps the map for a later --load-map (localise in it, or extend it; see yesslam-map),\n"
				"saved in the background every [System] checkpointSeconds (30) while the run goes and at its end.\n"
				"Ctrl-C stops the run and saves everything up to that frame. While it runs, trajectory_online.txt\n"
				"(in the map's own frame until the end) and frames.csv are a journal written frame by frame, and\n"
				"stats.json says \"complete\": false: a run killed outright (kill -9) keeps them to its last frame.",
				{"yesslam --input sim_walking --out run1   (a yesslam-sim folder: uses its detections.txt)",
				 "yesslam --input rgbd_dataset_freiburg3_walking_xyz --config share/mrpt_yesslam/config/tum_fr3.ini "
				 "--out run2 --detector yolo",
				 "yesslam --input walking.rawlog --out run3 --no-dynamic-filter   (the ORB-SLAM2-like baseline)",
				 "yesslam --input openni2 --out live1 --record live1.rawlog   (the first camera; replay: --input "
				 "live1.rawlog)",
				 "yesslam --input walking.rawlog --out run4 --realtime   (as a 30 fps camera would deliver it)",
				 "yesslam --input office_pass1 --out map1 --save-map office.ysm   (map once)",
				 "yesslam --input office_pass2 --out loc2 --load-map office.ysm --localize-only   (localise in it "
				 "later)",
				 "yesslam --list-devices"});
			cl.text("input", "PATH", ".rawlog, TUM RGB-D folder, or openni2[:URI|FILE.oni] (required)", &o.input);
			cl.text("out", "DIR", "output folder, created if missing (required)", &o.outDir);
			cl.flag("list-devices", "list the OpenNI2 cameras connected (URI, name, USB ids) and exit", &listDevices);
			cl.text("record", "FILE.rawlog",
					"write every frame read (live: every frame captured, dropped ones too) to a rawlog; also on "
					"Ctrl-C; an existing FILE is refused without --overwrite",
					&o.record);
			cl.flag("overwrite", "--record may replace an existing file", &o.overwrite);
			cl.flag("realtime",
					"recorded input: deliver frames at their recorded pace through the live path (frames dropped when "
					"SLAM falls behind)",
					&o.live.realtime);
			cl.number("speed", "X", "with --realtime or an .oni: playback speed, 1 = as recorded", &speed);
			cl.number("width", "PX", "OpenNI2 camera: image width (640)", &width);
			cl.number("height", "PX", "OpenNI2 camera: image height (480)", &height);
			cl.number("fps", "HZ", "OpenNI2 camera: frame rate (30)", &fps);
			cl.text("save-map", "MAP.ysm",
					"save the map (with its semantic OctoMap) for a later --load-map: at the end (also on Ctrl-C), and "
					"every [System] checkpointSeconds (30) while the run goes, atomically in the background, so that a "
					"killed run keeps the map of its last checkpoint",
					&o.saveMap);
			cl.text("load-map", "MAP.ysm",
					"start from a saved map: the first frames are placed in it by relocalisation, the trajectory is in "
					"its frame, and new keyframes extend it",
					&o.loadMap);
			cl.flag("localize-only",
					"with --load-map: only localise, never change the map (no keyframes, no dense map)", &localizeOnly);
			cl.text("config", "FILE",
					"INI/YAML config (sections as share/mrpt_yesslam/config/default.ini); options here win", &config);
			cl.text("detector", "B",
					"auto (detections.txt beside the input, else yolo with the configured model or the shipped "
					"Yolo-Fastest, else hog when no model is found), yolo, file, hog, none",
					&detector);
			cl.flag("no-loop-closure", "do not detect or close loops ([LoopClosing] enabled=false)", &noLoop);
			cl.flag("no-dense-map", "do not build the dense cloud and OctoMap ([DenseMapping] enabled=false)",
					&noDense);
			cl.number("octomap-resolution", "M",
					  "OctoMap voxel size in metres ([DenseMapping] octomapResolution, default 0.05): from the dense "
					  "cloud's voxel size ([DenseMapping] voxelSize, 0.02) up to 10; 0.02-0.2 is useful for rooms",
					  &octomapRes);
			cl.flag("no-dynamic-filter",
					"the baseline the method is compared with: no dynamic handling at all (no mask, no geometric or "
					"mover check, no see-through culling; people go into the dense map): every feature is used, as "
					"ORB-SLAM2 would",
					&noDynamic);
			cl.text("policy", "P", "keyframe policy: semantic (the paper's Algorithm 1) or orbslam (ORB-SLAM2's rules)",
					&policy);
			cl.count("max-frames", "N", "process at most N frames (0 = all)", &o.maxFrames);
			cl.count("skip-frames", "N", "recorded input: start N frames in (the ones before are read and dropped)",
					 &o.skipFrames);
			cl.text("gt", "FILE", "ground-truth trajectory (TUM format) to evaluate against", &o.groundTruth);
			cl.text("gt-format", "auto|tum|bonn",
					"what the ground truth's poses are: tum = the camera's; bonn = the Bonn RGB-D Dynamic dataset's "
					"motion-capture markers, converted to the camera with the dataset's transform; auto (default) = "
					"bonn when the file's folder or name says bonn (the dataset's rgbd_bonn_* folders), else tum",
					&gtFormat);
			cl.text("camera", "NAME|FILE",
					"TUM folders and OpenNI2 input: fr1, fr2, fr3 or a camera file ('fx fy cx cy [w h [depth_scale]]', "
					"then 'k1 k2 p1 p2 k3', "
					"then the rolling-shutter readout: seconds or a sensor, e.g. 'readout kinect1', xtion, global); a "
					"recording's NAME_camera.txt "
					"beside it is used by default. The run says which readout it used (summary, stats.json)",
					&camera);
			cl.text("world-frame", "zup|optical",
					"frame of every output ([System] worldFrame): zup = x forward, y left, z up, the floor at z = 0 "
					"when seen (default); optical = the first keyframe's camera (x right, y down, z forward); a loaded "
					"map keeps its own",
					&worldFrame);
			cl.flag("sequential", "run local mapping in the tracking thread ([System] parallel=false): deterministic",
					&sequential);
			cl.flag("quiet", "no progress line", &quiet);
			if (!cl.parse(argc, argv)) return 0;
			if (listDevices)
			{
				const auto devices = listOpenNI2Devices();
				if (devices.empty())
				{
					std::fprintf(stderr,
								 "yesslam: no OpenNI2 device found (plugged in? see lsusb; may this user open it? see "
								 "docs/tools.md, Live input)\n");
					return 1;
				}
				for (const auto& d : devices)
					std::printf("openni2:%s  %s %s  usb %04x:%04x\n", d.uri.c_str(), d.vendor.c_str(), d.name.c_str(),
								d.usbVendorId, d.usbProductId);
				return 0;
			}
			if (o.input.empty())
				throw InputError("", "--input is required (a .rawlog, a TUM folder or openni2[:URI]; see --help)");
			if (o.outDir.empty()) throw InputError("", "--out is required (see --help)");
			auto whole = [](double v, double lo, double hi, const char* name)
			{
				if (!(v >= lo && v <= hi && v == std::floor(v)))
					throw InputError("", std::string("--") + name + " must be a whole number in " +
											 std::to_string(static_cast<int>(lo)) + ".." +
											 std::to_string(static_cast<int>(hi)));
				return static_cast<int>(v);
			};
			o.live.width = whole(width, 1, 10000, "width");
			o.live.height = whole(height, 1, 10000, "height");
			o.live.fps = whole(fps, 1, 1000, "fps");
			if (!(speed > 0 && speed <= 100))
				throw InputError("", "--speed must be in (0, 100], got " + std::to_string(speed));
			o.live.speed = speed;
			if (o.live.realtime && isOpenNI2Input(o.input))
				throw InputError(
					"", "--realtime is for recorded input (.rawlog, TUM folder); OpenNI2 input is live already");
			// Options that would do nothing in this run are refused rather than silently ignored.
			if (cl.given("speed") && !o.live.realtime && !isOpenNI2Input(o.input))
				throw InputError("",
								 "--speed sets the pace of --realtime playback (or of an .oni recording): add "
								 "--realtime, or leave --speed out");
			for (const char* k : {"width", "height", "fps"})
				if (cl.given(k) && !isOpenNI2Input(o.input))
					throw InputError("", std::string("--") + k +
											 " sets an OpenNI2 camera's stream mode: recorded input keeps its own");
			if (!config.empty()) o.slam.loadFromFile(config);
			if (cl.given("detector") || config.empty()) o.slam.detector.backend = detector;
			o.groundTruthFormat = parseGroundTruthFormat(gtFormat);
			if (noDynamic) o.slam.system.dynamicFilter = false;
			if (noLoop) o.slam.loop.detection.enabled = false;
			if (noDense) o.slam.dense.enabled = false;
			if (cl.given("octomap-resolution"))
			{
				if (!(octomapRes >= 0.005 && octomapRes <= 10))
					throw InputError(
						"", "--octomap-resolution must be between 0.005 and 10 m, got " + std::to_string(octomapRes));
				o.slam.dense.octomapResolution = octomapRes;
			}
			if (!policy.empty()) o.slam.keyFrames.policy = policy;
			if (!worldFrame.empty())
			{
				if (worldFrame != "zup" && worldFrame != "optical")
					throw InputError("", "--world-frame is zup or optical, got '" + worldFrame + "'");
				o.slam.system.worldFrame = worldFrame;
			}
			if (!camera.empty()) o.slam.input.camera = camera;
			if (sequential) o.slam.system.parallel = false;
			if (localizeOnly)
			{
				o.slam.system.localizeOnly = true;
				o.slam.dense.enabled = false;  // no keyframes to build it from
			}

			// What a second Ctrl-C does depends on the phase: each phase's line made once, before
			// the handler may print it.
			// Never destroyed: the signal handler may print one after main returns.
			static auto* secondNote = new std::map<ESlamJobPhase, std::string>;
			for (auto p : {ESlamJobPhase::Frames, ESlamJobPhase::FinalMapping, ESlamJobPhase::Saving})
				(*secondNote)[p] = std::string("\nyesslam: ") + secondInterruptNote(p) + "\n";
			installInterruptHandler(
				"\nyesslam: stopping: finishing the map and saving the results (Ctrl-C again skips what is not yet "
				"written)\n",
				secondNote->at(ESlamJobPhase::Frames).c_str());
			// The bar's rate is the summary's fps: frames over the frame loop and the final mapping, not
			// the start-up or the outputs' writing.
			ProgressBar bar("yesslam", 0, !quiet, " fps");
			o.onPhase = [&bar](ESlamJobPhase p)
			{
				setAbortMessage(secondNote->at(p).c_str());
				if (p == ESlamJobPhase::Frames) bar.startClock();
				if (p == ESlamJobPhase::Saving) bar.stopClock();
			};
			const TSlamJobSummary s = runSlamJob(
				o,
				[&](std::size_t done, std::size_t total, const std::string& status)
				{
					bar.setTotal(total);
					bar.update(done, status);
				},
				[] { return interruptRequested(); }, [] { return abortRequested(); });
			bar.finish();
			const auto& st = s.stats;
			std::printf("detector:        %s\n", s.detector.c_str());
			if (!s.input.device.empty()) std::printf("camera:          %s\n", s.input.device.c_str());
			if (s.input.live)
				std::printf("live input:      %zu frames captured (%.1f fps), %zu dropped (%.1f%%)%s\n",
							s.input.stats.captured, s.input.stats.captureFps, s.input.stats.dropped,
							s.input.stats.captured ? 100.0 * static_cast<double>(s.input.stats.dropped) /
														 static_cast<double>(s.input.stats.captured)
												   : 0.0,
							s.input.disconnected ? "; the camera stopped delivering frames" : "");
			if (!o.record.empty())
				std::printf("recorded:        %zu frames to %s\n", s.input.recorded, o.record.c_str());
			if (!o.loadMap.empty())
				std::printf("map loaded:      %s (%s, %zu points)%s\n", o.loadMap.c_str(),
							countOf(s.mapFiles.loadedKeyFrames, "keyframe").c_str(), s.mapFiles.loadedPoints,
							o.slam.system.localizeOnly ? ", localisation only" : "");
			std::printf("frames:          %zu\n", st.frames);
			std::printf(
				"rolling shutter: %s\n",
				s.readout.source == "none"
					? "none (readout not known: no correction)"
					: (formatNumber(1000 * s.readout.seconds) + " ms readout, from " + s.readout.source).c_str());
			std::printf(
				"tracked:         %zu (%.1f%%), relocalisations %zu, weak poses refused %zu\n", st.trackedFrames,
				st.frames ? 100.0 * static_cast<double>(st.trackedFrames) / static_cast<double>(st.frames) : 0.0,
				st.relocalisations, st.refusedPoses);
			std::printf("fps:             %.2f (%.1f s)\n",
						s.seconds > 0 ? static_cast<double>(st.frames) / s.seconds : 0.0, s.seconds);
			std::printf(
				"keyframes:       %zu inserted (%zu forced), %zu culled as redundant, %zu in the map; map points %zu\n",
				st.keyFrames, st.forcedKeyFrames, st.culledKeyFrames, st.keyFramesInMap, st.mapPoints);
			if (o.slam.loop.detection.enabled)
				std::printf("loops:           %zu closed (%zu detected, %zu refused by geometry), %zu global BA\n",
							st.loopCorrections, st.loops.consistent, st.loops.rejectedGeometry, st.globalBundleApplied);
			else
				std::printf("loops:           loop closing off\n");
			if (o.slam.dense.enabled)
			{
				std::printf(
					"dense map:       %zu points (%zu outliers removed), octree %zu occupied / %zu free / %zu unknown "
					"leaves; .ply %.1f MB, .ot %.1f MB, "
					".bt %.2f MB (%.1f s)\n",
					s.dense.cloudPoints, s.dense.outliersRemoved, s.dense.occupiedLeaves, s.dense.freeLeaves,
					s.dense.unknownLeaves, s.dense.plyBytes / 1e6, s.dense.otBytes / 1e6, s.dense.btBytes / 1e6,
					s.dense.buildMs / 1000);
				if (!s.dense.gridProblem.empty())
					std::printf("2D grid:         %s\n", s.dense.gridProblem.c_str());
				else if (o.slam.grid.enabled && s.skippedOutputs.empty())
					std::printf(
						"2D grid:         %zu occupied / %zu free / %zu unknown cells of %.2f m%s (map_2d.*)\n",
						s.dense.gridOccupied, s.dense.gridFree, s.dense.gridUnknown, s.dense.gridResolution,
						s.dense.gridFloorSeen ? "" : "; no floor seen: the band measured from [Grid2D] cameraHeight");
				// A map with nothing occupied is no map for a planner: say why instead of a quiet file.
				if (s.dense.occupiedLeaves == 0 && s.skippedOutputs.empty())
					std::fprintf(stderr,
								 "yesslam: warning: the dense map has no occupied voxel: no surface was confirmed by "
								 "enough keyframes ([DenseMapping] "
								 "occupancyThreshold %.2f; %zu keyframes in the map); map.bt and map.ot mark what was "
								 "seen unknown, not free\n",
								 o.slam.dense.occupancyThreshold, st.keyFramesInMap);
			}
			if (s.mapFiles.loadedKeyFrames > 0 && o.slam.dense.enabled)
				std::printf(
					"                 %s\n",
					s.dense.priorMerged
						? "the octree continues the loaded map's (what this run saw replaces it)"
						: "note: the loaded map has no octree at this resolution: the octree holds this run only");
			std::printf(
				"outputs:         "
				"%s/"
				"{trajectory.txt,trajectory_online.txt,trajectory_smoothed.txt,keyframes.txt,frames.csv,map.3Dscene,"
				"stats.json,config_used.ini%s%s}\n",
				o.outDir.c_str(), o.slam.loop.detection.enabled ? ",loop_candidates.csv" : "",
				o.slam.dense.enabled
					? (o.slam.grid.enabled ? ",dense_cloud.ply,map.ot,map.bt,map_2d.{gridmap,pgm,yaml,png}"
										   : ",dense_cloud.ply,map.ot,map.bt")
					: "");
			if (!o.saveMap.empty() && s.mapFiles.saveError.empty() && s.mapFiles.savedBytes > 0)
				std::printf("map saved:       %s (%s, %zu points, %.1f MB)\n", o.saveMap.c_str(),
							countOf(st.keyFramesInMap, "keyframe").c_str(), st.mapPoints, s.mapFiles.savedBytes / 1e6);
			if (s.mapFiles.checkpoints > 0)
				std::printf("                 and %s while the run went (every %s s, the longest %.0f ms)\n",
							countOf(s.mapFiles.checkpoints, "checkpoint").c_str(),
							formatNumber(s.mapFiles.checkpointSeconds).c_str(), s.mapFiles.checkpointMaxMs);
			if (s.evaluated)
			{
				std::printf("ground truth:    %s (%s)\n", s.groundTruth.c_str(),
							describeGroundTruthFormat(s.groundTruthFormat).c_str());
				std::fputs(formatEvalKeyValues(s.eval).c_str(), stdout);
				if (!s.eval.hasRpe) std::fprintf(stderr, "yesslam: note: no RPE (%s)\n", s.eval.rpeProblem.c_str());
				// What a robot had while it moved (trajectory_online.txt), and the file smoothed after the run.
				const std::tuple<const char*, bool, const TEvalReport*> others[] = {
					{"online", s.evaluatedOnline, &s.evalOnline}, {"smoothed", s.evaluatedSmoothed, &s.evalSmoothed}};
				for (const auto& [prefix, done, e] : others)
				{
					if (!done) continue;
					std::printf("%s_ate_rmse: %.9f\n%s_jitter_median: %.9f\n", prefix, e->ate.stats.rmse, prefix,
								e->jitter.median);
					if (e->hasRpe)
						std::printf("%s_rpe_trans_rmse: %.9f\n%s_rpe_rot_rmse_deg: %.9f\n", prefix, e->rpe.trans.rmse,
									prefix, e->rpe.rotDeg.rmse);
				}
			}
			else if (!s.evalProblem.empty())
				std::fprintf(stderr, "yesslam: warning: no evaluation against %s: %s\n", s.groundTruth.c_str(),
							 s.evalProblem.c_str());
			for (const auto& w : s.warnings) std::fprintf(stderr, "yesslam: warning: %s\n", w.c_str());
			for (const auto& k : s.skippedOutputs)
				std::fprintf(stderr, "yesslam: not written (second Ctrl-C): %s\n", k.c_str());
			if (!s.mapFiles.saveError.empty())
			{
				std::fprintf(stderr, "yesslam: error: the map was not saved: %s\n", s.mapFiles.saveError.c_str());
				return 1;
			}
			if (s.interrupted)
			{
				std::fprintf(stderr, "yesslam: interrupted; results cover the first %zu frames\n", st.frames);
				return interruptExitCode();
			}
			return 0;
		});
}
