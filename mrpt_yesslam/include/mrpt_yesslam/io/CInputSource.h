#pragma once
// One interface for every place RGB-D frames come from (rawlog, TUM folder; later a live camera),
// so that the SLAM system and the tools never care which one they read.
#include <mrpt/config/CLoadableOptions.h>
#include <mrpt/obs/CObservation3DRangeScan.h>

#include "mrpt_yesslam/util/ConfigFile.h"

#include <memory>
#include <optional>
#include <string>
#include "mrpt_yesslam/util/OptionTable.h"

namespace mrpt_yesslam
{
/** A stream of RGB-D frames, read one at a time (never the whole sequence in memory). */
class CInputSource
{
   public:
	/** Settings shared by all sources; section [Input] of the config. */
	struct TOptions : public TTableOptions<TOptions>
	{
		/** TUM folders: camera name (fr1, fr2, fr3) or camera file; empty = calibration.txt in the
		 * folder, else the freiburg name in the folder path. */
		std::string camera;
		/** TUM folders: largest rgb/depth stamp difference to pair them, seconds (associate.py). */
		double maxDiff = 0.02;
		/** Rawlogs: only frames with this sensor label (empty = all 3D range scans). */
		std::string sensorLabel;
		/** Frames decoded ahead on a reader thread by the SLAM app (CPrefetchingSource); 0 = read
		 * in the processing thread. */
		int prefetch = 4;

		/** Every option once: key, member, range, help (load, dump and keys come from it). */
		COptionTable table();
	};

	virtual ~CInputSource() = default;
	/** The next frame, validated (colour + same-size depth), or nullptr at the end of the stream.
	 * Throws InputError naming the file for unreadable or inconsistent data. */
	virtual mrpt::obs::CObservation3DRangeScan::Ptr next() = 0;
	/** Number of frames the source expects to deliver; 0 when unknown (streamed rawlogs). */
	virtual std::size_t sizeHint() const { return 0; }
	/** Entries that were in the input but cannot become frames (unpaired rgb, non-RGB-D observations). */
	virtual std::size_t skipped() const { return 0; }
	/** The path the source reads. */
	virtual const std::string& path() const = 0;
	/** When the depth image delivered with the colour image stamped `colourTime` was taken, where
	 * the source knows it (TUM folders: depth.txt); none: with the colour image. Safe to call while
	 * next() runs on another thread (a prefetching reader). */
	virtual std::optional<double> depthTime(double colourTime) const
	{
		(void)colourTime;
		return std::nullopt;
	}
};

/** Opens a rawlog file (*.rawlog, gz-compressed or not) or a TUM RGB-D folder; throws InputError
 * when the path does not exist or is neither. */
std::unique_ptr<CInputSource> openInputSource(const std::string& path, const CInputSource::TOptions& opts = {});

/** The ground-truth file that belongs with an input: "groundtruth.txt" in a TUM folder, or
 * "<name>_groundtruth.txt" beside "<name>.rawlog" (as tum2rawlog writes it); empty if none. */
std::string findGroundTruthFor(const std::string& inputPath);

/** The rolling-shutter readout (seconds, first row to last) an input states: a sequence made by
 * yesslam-sim (its meta.json, in the folder or beside the rawlog) says its "readout_ms", and one
 * made before the simulator had a rolling shutter says nothing and was a global shutter (0).
 * None for anything else (recorded cameras say nothing about it). */
std::optional<double> statedReadout(const std::string& inputPath);

/** A rolling-shutter readout and where it came from, in words. */
struct TReadout
{
	double seconds = 0;
	std::string source;
};
/** The rolling-shutter readout of an input's camera where it is known: for OpenNI2 input the
 * --camera ([Input] camera) it names, a recording's camera file (recordingCameraPath), what a
 * simulated sequence states (statedReadout), a TUM folder's camera (TUM presets and Bonn folders
 * 0.028 s, a camera file's readout line), an OpenNI2 device's design (deviceReadout). None for
 * cameras of unknown readout and for a folder whose camera cannot be found (opening it says why). */
std::optional<TReadout> knownReadout(const std::string& inputPath, const CInputSource::TOptions& opts);
/** The readout a run on `inputPath` corrects for, as yesslam decides it: `configured` ([Tracking]
 * rollingShutter) when >= 0, else the input camera's (knownReadout), else none (0 s, source
 * "none"). A program on the library sets [Tracking] rollingShutter from it to run as the app. */
TReadout resolveReadout(double configured, const std::string& inputPath, const CInputSource::TOptions& opts);
}  // namespace mrpt_yesslam
