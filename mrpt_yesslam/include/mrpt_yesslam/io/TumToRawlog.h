#pragma once
// The conversion behind rawlog_tools/tum2rawlog, in the library so tests can call it.
#include <cstdint>
#include <functional>
#include <string>

#include "mrpt_yesslam/io/CInputSource.h"

namespace mrpt_yesslam
{
/** What tum2rawlog does: which folder, which file, how. */
struct TTumToRawlogOptions
{
	std::string folder;            //!< TUM RGB-D folder
	std::string output;            //!< .rawlog to write
	CInputSource::TOptions input;  //!< camera, pairing window
	bool externalImages = false;   //!< colour images as PNG files in "<name>_Images/" instead of inline
	std::size_t maxFrames = 0;     //!< 0 = all
};

/** What a conversion produced. */
struct TTumToRawlogSummary
{
	std::size_t frames = 0;        //!< frames written
	std::size_t skipped = 0;       //!< rgb entries without a depth image within the window
	double tFirst = 0, tLast = 0;  //!< stamps of the first and last frame, s
	std::uintmax_t bytes = 0;      //!< size of the rawlog (plus external images), bytes
	std::string groundTruth;       //!< copy of groundtruth.txt beside the rawlog, empty if none
	std::string imagesDir;         //!< external images folder, empty if inline
	std::string camera;            //!< camera model used
	/** The camera file written beside the rawlog (recordingCameraPath: its readout goes with it). */
	std::string cameraFile;
	bool interrupted = false;  //!< stopped early by the cancel callback; the file holds what was done
};

/** Converts a TUM folder to a rawlog; `progress(done,total)` is called after every frame, and
 * when `cancel()` turns true the frames so far are saved and the conversion stops.
 * Throws InputError naming the offending file. */
TTumToRawlogSummary convertTumToRawlog(const TTumToRawlogOptions& opts,
									   const std::function<void(std::size_t, std::size_t)>& progress = {},
									   const std::function<bool()>& cancel = {});
}  // namespace mrpt_yesslam
