#pragma once
// Frames from an OpenNI2 camera (Kinect for Xbox 360 through libfreenect's OpenNI2 driver, ASUS
// Xtion, Orbbec Astra, PrimeSense Carmine) or from an .oni recording played by OpenNI2's own file
// driver. OpenNI2 is used directly, not through MRPT's COpenNI2Sensor: that wrapper opens devices
// by index only (no URI, so no .oni files), gives no playback control, and its destructor throws
// when no device is present.
#include <atomic>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "mrpt_yesslam/io/CInputSource.h"
#include "mrpt_yesslam/io/RgbdCamera.h"

namespace mrpt_yesslam
{
/** Maps a device's frame times (microseconds since the device started) onto the host's clock
 * once, at the first frame: host time then + device time since. Frames keep the device's own
 * spacing (no pairing or USB latency jitter), the clock never jumps with NTP, and the times are
 * comparable with other host-stamped data. */
class CDeviceClock
{
   public:
	/** Host time (s) of a frame the device stamped `deviceMicros`, `hostNow` being the host's
	 * clock when it arrived (used for the anchor). */
	double toHost(std::uint64_t deviceMicros, double hostNow);

   private:
	bool anchored_ = false;
	std::uint64_t deviceAnchor_ = 0;
	double hostAnchor_ = 0;
};

/** One OpenNI2 device as `yesslam --list-devices` shows it. */
struct TOpenNI2Device
{
	std::string uri, name, vendor;
	int usbVendorId = 0, usbProductId = 0;
};

/** The rolling-shutter readout of a device, from its name and USB ids, where known: PrimeSense
 * designs (Kinect v1, ASUS Xtion, Carmine: 0.028 s, Kerl et al., ICCV 2015) say so; none for others
 * (an Orbbec Astra has no published readout we know of). */
std::optional<double> deviceReadout(const TOpenNI2Device& d);

/** The OpenNI2 devices connected now (initialises OpenNI2; throws InputError if it cannot). */
std::vector<TOpenNI2Device> listOpenNI2Devices();

/** Whether an --input value names the OpenNI2 source ("openni2" or "openni2:URI"). */
bool isOpenNI2Input(const std::string& input);

/** An RGB-D stream of one OpenNI2 device or .oni file; not thread-safe (one reader thread). */
class COpenNI2Source : public CInputSource
{
   public:
	/** Camera settings ([Input] openni2* keys and yesslam's --width/--height/--fps). */
	struct TOptions
	{
		std::string uri;                          //!< device URI or .oni path; empty = the first device
		int width = 640, height = 480, fps = 30;  //!< devices only (a file plays what it holds)
		/** Files: 1 = as recorded (a camera's timing), -1 = one frame per request (nothing is
		 * lost, for deterministic replays). Devices ignore it. */
		double playbackSpeed = 1.0;
		/** Intrinsics: empty = from the colour stream's field of view; else a camera file or a
		 * TUM name (fr1, fr2, fr3), as --camera. */
		std::string camera;
		double timeoutSeconds = 5.0;  //!< no frame for this long: the device is gone (a file: it ended)
	};

	/** Opens the device or file and starts its depth and colour streams (depth registered to
	 * colour). Throws InputError with one line: no device, file missing, unsupported mode. */
	explicit COpenNI2Source(const TOptions& opts);
	~COpenNI2Source() override;
	COpenNI2Source(const COpenNI2Source&) = delete;
	COpenNI2Source& operator=(const COpenNI2Source&) = delete;

	/** The next depth + colour pair; nullptr at the end of a file or when a device stops
	 * delivering (unplugged: `disconnected()` tells which). */
	mrpt::obs::CObservation3DRangeScan::Ptr next() override;
	std::size_t sizeHint() const override;
	const std::string& path() const override { return path_; }

	/** The intrinsics frames carry. */
	const TRgbdCamera& camera() const { return camera_; }
	/** Device name and stream modes, for the log. */
	const std::string& description() const { return description_; }
	/** Whether an .oni file is played. */
	bool isFile() const;
	/** A device stopped delivering frames before the run ended. */
	bool disconnected() const { return disconnected_; }
	/** Frames of one stream that found no partner of the other within half a frame period. */
	std::size_t skipped() const override { return unpaired_; }

   private:
	struct TImpl;
	std::unique_ptr<TImpl> impl_;
	std::string path_, description_;
	TRgbdCamera camera_;
	std::atomic<bool> disconnected_{false};  //!< written by the reading thread, read by any
	std::atomic<std::size_t> unpaired_{0};   //!< skipped(): written by the reading thread
	CDeviceClock clock_;
	bool ended_ = false;
	int timeoutMs_ = 5000;
};
}  // namespace mrpt_yesslam
