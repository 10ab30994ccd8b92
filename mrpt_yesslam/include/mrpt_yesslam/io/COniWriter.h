#pragma once
// Writes RGB-D frames as an OpenNI2 recording (.oni) that OpenNI2's own file driver (libOniFile,
// Debian's libopenni2-0) plays: one depth and one colour stream, uncompressed, with the record
// layout, node properties and seek tables OpenNI2's recorder writes. Its use: the live path
// (yesslam --input openni2:FILE.oni) is tested through the real OpenNI2 stack without a camera,
// and recorded datasets can be fed to any OpenNI2 application.
//
// Unlike OpenNI2's recorder, frame times are written as given (microseconds since the Unix epoch
// for TUM and yesslam-sim data), so ground truth and detection files still match the frames.
// Depth is stored in OpenNI2's 100 um units when the source's units convert exactly (TUM's 1/5000
// m does), else in millimetres; depth beyond the 16-bit range (6.55 m or 65.5 m) is stored as 0.
#include <mrpt/obs/CObservation3DRangeScan.h>

#include <cstdint>
#include <fstream>
#include <functional>

#include "mrpt_yesslam/io/CInputSource.h"
#include <string>
#include <vector>

namespace mrpt_yesslam
{
/** Which streams a frame writes, and when its colour was taken: a camera's recording has colour
 * and depth at slightly different times and now and then a frame of one stream only. */
struct TOniStreams
{
	bool depth = true, colour = true;
	double colourDelay = 0;  //!< s: the colour frame's time after the depth frame's (the observation's time)
};

/** Appends frames to a new .oni file, written atomically (temp file renamed by finish()). */
class COniWriter
{
   public:
	/** Opens "<path>.tmp.<pid>"; throws InputError naming `path` if it cannot. */
	explicit COniWriter(const std::string& path);
	/** Removes the temporary file unless finish() was called. */
	~COniWriter();
	COniWriter(const COniWriter&) = delete;
	COniWriter& operator=(const COniWriter&) = delete;

	/** Writes one registered RGB-D frame; the first fixes size, depth unit and field of view,
	 * later frames must match them (InputError otherwise: one recording has one depth unit). */
	void write(const mrpt::obs::CObservation3DRangeScan& obs, const TOniStreams& streams = {});
	/** Seek tables, final node records and the end record; the streams' frame rate from the
	 * frames' times (their median interval; 30 for a single frame); renames the file into place.
	 * Returns its size in bytes. Throws InputError when no frame was written. */
	std::uintmax_t finish();

	std::size_t frames() const { return frames_; }          //!< frames written so far
	std::size_t clippedPixels() const { return clipped_; }  //!< depth pixels beyond the range, stored as 0
	bool depthIn100um() const { return unit100um_; }        //!< the depth unit chosen from the first frame
	unsigned framesPerSecond() const { return fps_; }       //!< the frame rate finish() wrote

   private:
	/** One stream (node) of the recording. */
	struct TNode
	{
		std::uint32_t id = 0;
		bool depth = false;
		std::uint64_t addedPos = 0, lastDataPos = 0, lastPropPos = 0;
		std::vector<std::uint64_t> stamps, positions;
		std::vector<std::uint64_t> fpsPositions;  //!< where the video modes' frame rates lie (set by finish())
	};
	void start(const mrpt::obs::CObservation3DRangeScan& first);
	void writeRecord(std::uint32_t type, std::uint32_t node, std::uint64_t undo, const std::string& fields,
					 const void* payload, std::size_t payloadSize);
	void nodeAdded(const TNode& n, std::uint32_t frames, std::uint64_t minStamp, std::uint64_t maxStamp,
				   std::uint64_t seekTable);
	void property(TNode& n, const std::string& name, const void* data, std::size_t size, bool integer);
	void newData(TNode& n, std::uint64_t stamp, const void* data, std::size_t size);

	std::string path_, tmp_;
	std::ofstream out_;
	bool started_ = false, finished_ = false, unit100um_ = true;
	int width_ = 0, height_ = 0;
	double depthFactor_ = 1;  //!< OpenNI2 units per raw unit of the source
	float firstUnits_ = 0;    //!< the first frame's depth unit (m per raw unit): every frame's
	unsigned fps_ = 0;
	std::size_t frames_ = 0, clipped_ = 0;
	TNode depth_, color_;
	std::vector<std::uint16_t> depthBuf_;
	std::vector<std::uint8_t> rgbBuf_;
};

/** What convertToOni wrote. */
struct TOniConversion
{
	std::size_t frames = 0, clippedPixels = 0;
	bool depthIn100um = true;
	double tFirst = 0, tLast = 0;
	std::uintmax_t bytes = 0;
	std::string groundTruth;  //!< the ground truth copied beside the output, empty if none
	/** The camera file written beside the output (recordingCameraPath): the input's intrinsics,
	 * distortion and readout, which an .oni cannot hold; `yesslam --input openni2:OUT.oni` reads it. */
	std::string cameraFile;
	/** The input's detections.txt copied beside the output (where `yesslam --input openni2:OUT.oni`
	 * looks for it), empty if none; `detectionsNote` says why one was not copied. */
	std::string detections, detectionsNote;
	bool interrupted = false;
};

/** Converts a rawlog or TUM folder into an .oni file (yesslam-oni), creating its folder; the input's
 * ground truth is copied to "<name>_groundtruth.txt" beside it, which yesslam finds for
 * "openni2:<name>.oni", and its detections.txt to detections.txt there (never over a different one).
 * `progress(done, total)` after each frame; `cancel()` ends early and keeps what was written. */
TOniConversion convertToOni(const std::string& input, const std::string& output,
							const CInputSource::TOptions& inputOptions, std::size_t maxFrames = 0,
							const std::function<void(std::size_t, std::size_t)>& progress = {},
							const std::function<bool()>& cancel = {});
}  // namespace mrpt_yesslam
