// TYesSlamOptions: the sections of the system's own options, loading a configuration file, its dump.
#include "mrpt_yesslam/system/CYesSlamSystem.h"

#include <mrpt/config/CConfigFileBase.h>

#include <algorithm>
#include <sstream>

#include "mrpt_yesslam/util/ConfigFile.h"
#include "mrpt_yesslam/util/Error.h"
#include "mrpt_yesslam/util/TextParsing.h"

namespace mrpt_yesslam
{
COptionTable TYesSlamOptions::TSystem::table()
{
	COptionTable t("System");
	t.flag("parallel", parallel, "local mapping in its own thread (false: sequential, deterministic)");
	t.flag("dynamicFilter", dynamicFilter,
		   "dynamic-object handling (false: the baseline, no dynamic mechanism at all: no mask, no geometric or mover "
		   "check, no see-through culling, people go into the dense map; every feature is used, as ORB-SLAM2)");
	t.count("minInitPoints", minInitPoints, 10, 100000, "static keypoints with depth needed for the first keyframe");
	t.count("frameBuffer", frameBuffer, 1, 10000,
			"recent frames kept for delayed (semantic) keyframe decisions (>= [KeyFrames] interval)");
	t.flag("asyncDetection", asyncDetection, "detect on a worker thread while ORB features are extracted");
	t.count("mappingQueue", mappingQueue, 1, 10000,
			"parallel: keyframes waiting for local mapping before tracking waits");
	t.text("keyFrameFramePose", keyFrameFramePose,
		   "trajectory.txt at a keyframe's own frame: tracked (the keyframe it was tracked against, as every frame; "
		   "the default, measured better on real frames) or keyframe (the keyframe's final pose, as ORB-SLAM2 and "
		   "keyframes.txt)",
		   {"tracked", "keyframe"});
	t.flag("localizeOnly", localizeOnly,
		   "localisation in a loaded map only (yesslam --load-map): no keyframes, the map is not changed");
	t.text("worldFrame", worldFrame,
		   "frame of every export: zup (x forward, y left, z up; floor at z = 0 when seen) or optical (the first "
		   "keyframe's camera: x right, y down, z forward); a loaded map keeps its own",
		   {"zup", "optical"});
	t.real("checkpointSeconds", checkpointSeconds, 0, 1e6,
		   "with a map file to save (yesslam --save-map): the map is saved to it this often, in the background, while "
		   "the run goes, so that a killed run keeps its map (seconds of wall time; 0 = at the end only)");
	return t;
}

COptionTable TYesSlamOptions::TOutput::table()
{
	COptionTable t("Output");
	t.flag("lostInterpolate", lostInterpolate,
		   "trajectory_smoothed.txt: lost frames between two tracked ones are placed between them by time once "
		   "tracking resumes (trajectory.txt keeps the coasted pose)");
	t.integer("correctionWindow", correctionWindow, 0, 1000,
			  "trajectory_smoothed.txt: what mapping moved each tracked frame by since it was tracked (its keyframe's "
			  "correction) is averaged over this many tracked frames either side and applied to the pose tracking "
			  "measured (0: off)");
	t.integer("smoothingWindow", smoothingWindow, 0, 1000,
			  "trajectory_smoothed.txt: each tracked frame's position is the value at its stamp of a parabola fitted "
			  "in time through up to this many tracked frames either side, as many on each side (a side ends at a loop "
			  "correction, a relocalisation, a lost frame or this many fifteenths of a second), so it uses up to this "
			  "many LATER frames; orientation its own (0: off)");
	return t;
}

void TYesSlamOptions::loadFromFile(const std::string& path)
{
	// What MRPT would ignore without a word also warns: a broken section line, keys before any
	// section, and a section we do not read (a misspelt [Trackng] leaves its keys at their defaults).
	std::vector<std::string> warnings;
	const auto cfg = loadConfigFile(path, &warnings);  // parsed once for all sections
	for (const auto& w : warnings) printWarning(w);
	warnings.clear();
	std::vector<std::string> known;
	const auto load =
		[&](const char* section, mrpt::config::CLoadableOptions& opts, const std::vector<TConfigKey>& keys)
	{
		known.push_back(section);
		loadOptions(*cfg, path, section, opts, keys);
	};
	// One depth-noise model since issue 42: its three former keys would be ignored with a warning,
	// silently changing what a configuration (paper.ini's depthNoise = 0) measures.
	for (const auto& [section, key] : {std::pair<const char*, const char*>{"Tracking", "depthNoise"},
									   {"LocalMapping", "depthNoise"},
									   {"LoopClosing", "refineDepthNoise"}})
		if (cfg->sectionExists(section) && !cfg->read_string(section, key, "").empty())
			throw InputError(path, std::string("[") + section + "] " + key +
									   " is now [Camera] depthNoise: one depth-noise model for every stage");
	// The after-the-run smoothing shapes trajectory_smoothed.txt only since issue 62: ignored with a
	// warning, a configuration that turned it off would silently measure something else.
	for (const char* key : {"lostInterpolate", "correctionWindow", "smoothingWindow"})
		if (cfg->sectionExists("Tracking") && !cfg->read_string("Tracking", key, "").empty())
			throw InputError(path, std::string("[Tracking] ") + key + " is now [Output] " + key +
									   ": it shapes trajectory_smoothed.txt only (trajectory.txt is never smoothed)");
	load("Camera", camera, TDepthNoise::configKeys());
	load("Input", input, CInputSource::TOptions::configKeys());
	load("Detector", detector, CObjectDetector::TOptions::configKeys());
	load("DynamicMask", masker, CDynamicObjectMasker::TOptions::configKeys());
	load("GeometricCheck", geometric, CGeometricDynamicCheck::TOptions::configKeys());
	load("ORB", orb, COrbExtractor::TOptions::configKeys());
	load("Tracking", tracking, CTracker::TOptions::configKeys());
	load("OnlinePose", onlinePose, COnlinePoseFilter::TOptions::configKeys());
	load("KeyFrames", keyFrames, CKeyFrameInserter::TOptions::configKeys());
	load("LocalMapping", mapping, CLocalMapper::TOptions::configKeys());
	load("LoopClosing", loop, CLoopCloser::TOptions::configKeys());
	load("DenseMapping", dense, CDenseSemanticMapper::TOptions::configKeys());
	load("Grid2D", grid, COccupancyGridBuilder::TOptions::configKeys());
	load("System", system, TSystem::configKeys());
	load("Output", output, TOutput::configKeys());
	std::vector<std::string> sections;
	cfg->getAllSections(sections);
	std::string list;
	for (const auto& k : known) list += (list.empty() ? "" : ", ") + k;
	for (const auto& sec : sections)
		// A section line without its ']' makes MRPT read the next lines into the name: already
		// reported above as the broken line it is, not as a second, garbled warning.
		if (!sec.empty() && sec.find_first_of("\n=") == std::string::npos &&
			std::none_of(known.begin(), known.end(),
						 [&](const std::string& k) { return lowerAscii(k) == lowerAscii(sec); }))
			warnings.push_back(path + ": unknown section [" + sec + "] ignored (known: " + list + ")");
	for (const auto& w : warnings) printWarning(w);
}

std::string TYesSlamOptions::dump() const
{
	std::ostringstream o;
	for (const mrpt::config::CLoadableOptions* p : std::initializer_list<const mrpt::config::CLoadableOptions*>{
			 &camera, &input, &detector, &masker, &geometric, &orb, &tracking, &onlinePose, &keyFrames, &mapping, &loop,
			 &dense, &grid, &system, &output})
	{
		p->dumpToTextStream(o);
		o << "\n";
	}
	return o.str();
}

TYesSlamOptions TYesSlamOptions::effective() const
{
	TYesSlamOptions o = *this;
	// The box part of the geometric check where it helps: a read-only map cannot cull what people
	// left in it, while mapping it took away the background between people (CGeometricDynamicCheck.h).
	if (o.geometric.boxes == "auto") o.geometric.boxes = o.system.localizeOnly ? "true" : "false";
	if (o.system.dynamicFilter) return o;
	// One switch for the baseline: the checks added beside the mask (issue 14) are dynamic handling too, and left on
	// they made "--no-dynamic-filter" far better than the ORB-SLAM2 it stands for.
	o.geometric.enabled = false;  // uncertain keypoints, the certain-first solve, movers (markMovers too)
	o.geometric.movers = false;
	o.geometric.boxes = "false";
	o.tracking.seeThroughFrames = 0;    // map points a person carried away are not culled
	o.masker.holdFrames = 0;            // unused without a mask; zero so that config_used.ini says so
	o.dense.dynamicExclusion = "none";  // people go into the dense map
	o.dense.dynamicHoldKeyFrames = 0;
	return o;
}
}  // namespace mrpt_yesslam
