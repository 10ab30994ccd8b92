#include "mrpt_yesslam/io/COpenNI2Source.h"

#include <OpenNI.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <mutex>
#include <stdlib.h>
#include <opencv2/imgproc.hpp>

#include "mrpt_yesslam/io/RgbdObservation.h"
#include "mrpt_yesslam/util/Error.h"

namespace fs = std::filesystem;

namespace mrpt_yesslam
{
namespace
{
const std::string kWhere = "openni2";

// OpenNI2's extended errors hold tabs and line breaks: one line, trimmed.
std::string oneLine(std::string s)
{
	for (char& c : s)
		if (c == '\n' || c == '\t' || c == '\r') c = ' ';
	const auto a = s.find_first_not_of(' '), b = s.find_last_not_of(' ');
	return a == std::string::npos ? std::string() : s.substr(a, b - a + 1);
}

// OpenNI2 keeps a device URI in a fixed 256-byte buffer and its file driver crashes on a path with
// bytes outside printable ASCII (SIGSEGV inside libOpenNI2 on "tü.oni"), so such a recording is
// opened through a short ASCII symbolic link in a private temporary folder (0700, made by
// mkdtemp), removed again when the source closes.
bool openNI2CanOpenAsIs(const std::string& path)
{
	if (path.size() >= 200) return false;  // well inside ONI_MAX_STR with the driver's own prefix
	return std::all_of(path.begin(), path.end(), [](char c) { return c >= 0x20 && c < 0x7f; });
}

class CShortLink
{
   public:
	// A link to `target` whose path OpenNI2 can open; throws InputError naming `target`.
	explicit CShortLink(const std::string& target)
	{
		std::error_code ec;
		std::string base = fs::temp_directory_path(ec).string();
		if (ec || !openNI2CanOpenAsIs(base + "/yesslam-oni-XXXXXX/recording.oni")) base = "/tmp";
		std::string tmpl = base + "/yesslam-oni-XXXXXX";
		if (!::mkdtemp(tmpl.data()))
			throw InputError(target,
							 "its path is not plain ASCII or is too long for OpenNI2, and no temporary folder for a "
							 "short link to it could be made in " +
								 base);
		dir_ = tmpl;
		link_ = dir_ + "/recording.oni";
		fs::create_symlink(fs::absolute(target), link_, ec);
		if (ec)
		{
			remove();
			throw InputError(target,
							 "its path is not plain ASCII or is too long for OpenNI2, and a short link to it failed: " +
								 ec.message());
		}
	}
	~CShortLink() { remove(); }
	CShortLink(const CShortLink&) = delete;
	CShortLink& operator=(const CShortLink&) = delete;
	const std::string& path() const { return link_; }

   private:
	void remove()
	{
		std::error_code ec;
		if (!link_.empty()) fs::remove(link_, ec);
		if (!dir_.empty()) fs::remove(dir_, ec);
	}
	std::string dir_, link_;
};

// OpenNI2 is initialised once per process and never shut down: its shutdown unloads drivers that
// other streams of the same process may still use.
void initOpenNI2()
{
	static std::once_flag once;
	static std::string problem;
	std::call_once(once,
				   []
				   {
					   if (openni::OpenNI::initialize() != openni::STATUS_OK)
						   problem = "cannot initialise OpenNI2: " + oneLine(openni::OpenNI::getExtendedError());
				   });
	if (!problem.empty()) throw InputError(kWhere, problem);
}

std::string modeText(const openni::VideoMode& m)
{
	return std::to_string(m.getResolutionX()) + "x" + std::to_string(m.getResolutionY()) + "@" +
		   std::to_string(m.getFps());
}

bool isDepthFormat(openni::PixelFormat f)
{
	return f == openni::PIXEL_FORMAT_DEPTH_1_MM || f == openni::PIXEL_FORMAT_DEPTH_100_UM;
}

// Picks the stream's mode of the wanted size and rate in an accepted pixel format.
void chooseMode(openni::VideoStream& s, int w, int h, int fps, bool depth, const std::string& what)
{
	const auto& modes = s.getSensorInfo().getSupportedVideoModes();
	std::string offered;
	for (int i = 0; i < modes.getSize(); i++)
	{
		const openni::VideoMode& m = modes[i];
		const bool format =
			depth ? isDepthFormat(m.getPixelFormat()) : m.getPixelFormat() == openni::PIXEL_FORMAT_RGB888;
		if (!format) continue;
		if (offered.find(modeText(m)) == std::string::npos) offered += (offered.empty() ? "" : ", ") + modeText(m);
		if (m.getResolutionX() == w && m.getResolutionY() == h && m.getFps() == fps)
		{
			if (s.setVideoMode(m) != openni::STATUS_OK)
				throw InputError(kWhere, "the " + what + " stream refused " + modeText(m) + ": " +
											 oneLine(openni::OpenNI::getExtendedError()));
			return;
		}
	}
	throw InputError(kWhere, "the " + what + " stream has no " + std::to_string(w) + "x" + std::to_string(h) + "@" +
								 std::to_string(fps) +
								 " mode (offered: " + (offered.empty() ? "none in a usable format" : offered) +
								 "; use --width/--height/--fps)");
}
}  // namespace

double CDeviceClock::toHost(std::uint64_t deviceMicros, double hostNow)
{
	// Re-anchored when the device clock runs backwards (a reset, a reconnect) or stands still
	// more than a minute behind the host (a suspended device).
	const double sinceAnchor = (static_cast<double>(deviceMicros) - static_cast<double>(deviceAnchor_)) * 1e-6;
	if (!anchored_ || deviceMicros < deviceAnchor_ || hostNow - (hostAnchor_ + sinceAnchor) > 60)
	{
		anchored_ = true;
		deviceAnchor_ = deviceMicros;
		hostAnchor_ = hostNow;
		return hostNow;
	}
	return hostAnchor_ + sinceAnchor;
}

struct COpenNI2Source::TImpl
{
	std::unique_ptr<CShortLink> link;  //!< declared first: outlives the device that reads through it
	openni::Device device;
	openni::VideoStream depth, color;
	openni::VideoFrameRef lastDepth, lastColor;
	int depthFrames = 0, colorFrames = 0;  //!< files: frames in each stream
	int depthRead = 0, colorRead = 0;
	bool manual = false;
	std::chrono::steady_clock::time_point start;
};

std::vector<TOpenNI2Device> listOpenNI2Devices()
{
	initOpenNI2();
	openni::Array<openni::DeviceInfo> list;
	openni::OpenNI::enumerateDevices(&list);
	std::vector<TOpenNI2Device> out;
	for (int i = 0; i < list.getSize(); i++)
	{
		TOpenNI2Device d;
		d.uri = list[i].getUri();
		d.name = list[i].getName();
		d.vendor = list[i].getVendor();
		d.usbVendorId = list[i].getUsbVendorId();
		d.usbProductId = list[i].getUsbProductId();
		out.push_back(d);
	}
	return out;
}

std::optional<double> deviceReadout(const TOpenNI2Device& d)
{
	std::string words = d.vendor + " " + d.name;
	std::transform(words.begin(), words.end(), words.begin(),
				   [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
	// A Kinect v2 / Kinect for Xbox One (time of flight, libfreenect2's driver) is another design.
	if (words.find("v2") != std::string::npos || words.find("one") != std::string::npos ||
		(d.usbVendorId == 0x045e && d.usbProductId >= 0x02c4))
		return std::nullopt;
	// USB ids: PrimeSense 0x1d27 (Xtion, Carmine); Microsoft 0x045e with the Kinect v1 camera's
	// products 0x02ae (Xbox 360) and 0x02bf (Kinect for Windows).
	const bool primeSense =
		d.usbVendorId == 0x1d27 || (d.usbVendorId == 0x045e && (d.usbProductId == 0x02ae || d.usbProductId == 0x02bf));
	for (const char* n : {"primesense", "xtion", "carmine", "kinect", "ps1080"})
		if (primeSense || words.find(n) != std::string::npos) return sensorReadout("primesense");
	return std::nullopt;
}

bool isOpenNI2Input(const std::string& input)
{
	return input == "openni2" || input.rfind("openni2:", 0) == 0;
}

COpenNI2Source::COpenNI2Source(const TOptions& o) : impl_(std::make_unique<TImpl>())
{
	path_ = o.uri.empty() ? "openni2" : "openni2:" + o.uri;
	const bool file = !o.uri.empty() && (fs::exists(o.uri) || fs::path(o.uri).extension() == ".oni");
	if (file && !fs::is_regular_file(o.uri)) throw InputError(o.uri, "not found (an .oni recording was expected)");
	if (!(o.timeoutSeconds > 0)) throw InputError(kWhere, "the frame timeout must be > 0 s");
	initOpenNI2();
	std::string uri = o.uri;
	if (!file)
	{
		const auto devices = listOpenNI2Devices();
		if (devices.empty())
			throw InputError(
				kWhere,
				"no OpenNI2 device found (is the camera plugged in - see lsusb - and may this user open it? "
				"Debian's libopenni2-0 installs the udev rules; replug after installing)");
		if (uri.empty()) uri = devices.front().uri;
	}
	if (file && !openNI2CanOpenAsIs(uri))
	{
		impl_->link = std::make_unique<CShortLink>(uri);
		uri = impl_->link->path();
	}
	if (impl_->device.open(uri.c_str()) != openni::STATUS_OK)
	{
		const std::string why = oneLine(openni::OpenNI::getExtendedError());
		throw InputError(file ? o.uri : kWhere,
						 file ? "OpenNI2's file driver cannot play it (not an OpenNI recording, or cut short)"
							  : "cannot open device " + uri + (why.empty() ? std::string() : ": " + why));
	}
	auto& dev = impl_->device;
	if (!dev.hasSensor(openni::SENSOR_DEPTH) || !dev.hasSensor(openni::SENSOR_COLOR))
		throw InputError(file ? o.uri : kWhere, "needs both a depth and a colour stream");
	if (impl_->depth.create(dev, openni::SENSOR_DEPTH) != openni::STATUS_OK ||
		impl_->color.create(dev, openni::SENSOR_COLOR) != openni::STATUS_OK)
		throw InputError(file ? o.uri : kWhere,
						 std::string("cannot create the streams: ") + oneLine(openni::OpenNI::getExtendedError()));
	if (!file)
	{
		chooseMode(impl_->depth, o.width, o.height, o.fps, true, "depth");
		chooseMode(impl_->color, o.width, o.height, o.fps, false, "colour");
		if (!dev.isImageRegistrationModeSupported(openni::IMAGE_REGISTRATION_DEPTH_TO_COLOR))
			throw InputError(kWhere, "the device cannot register depth to colour (every frame must be registered)");
		dev.setImageRegistrationMode(openni::IMAGE_REGISTRATION_DEPTH_TO_COLOR);
		dev.setDepthColorSyncEnabled(true);
		impl_->depth.setMirroringEnabled(false);
		impl_->color.setMirroringEnabled(false);
	}
	else if (auto* pc = dev.getPlaybackControl())
	{
		pc->setRepeatEnabled(false);
		impl_->manual = o.playbackSpeed < 0;
		pc->setSpeed(static_cast<float>(impl_->manual ? -1.0 : o.playbackSpeed));
		impl_->depthFrames = pc->getNumberOfFrames(impl_->depth);
		impl_->colorFrames = pc->getNumberOfFrames(impl_->color);
	}
	const openni::VideoMode dm = impl_->depth.getVideoMode(), cm = impl_->color.getVideoMode();
	if (!isDepthFormat(dm.getPixelFormat()))
		throw InputError(file ? o.uri : kWhere, "the depth stream is not in millimetres or 100 um units");
	if (cm.getPixelFormat() != openni::PIXEL_FORMAT_RGB888)
		throw InputError(file ? o.uri : kWhere, "the colour stream is not RGB888");
	if (dm.getResolutionX() != cm.getResolutionX() || dm.getResolutionY() != cm.getResolutionY())
		throw InputError(file ? o.uri : kWhere, "depth (" + modeText(dm) + ") and colour (" + modeText(cm) +
													") differ in size: depth must be registered to colour");

	// A recording's own camera file (recordingCameraPath: its distortion and readout, which an
	// .oni cannot hold) unless --camera names another.
	std::string cameraSpec = o.camera;
	if (cameraSpec.empty() && file)
		if (const std::string side = recordingCameraPath(o.uri); fs::is_regular_file(side)) cameraSpec = side;
	if (!cameraSpec.empty())
	{
		camera_ = fs::exists(cameraSpec) ? readCameraFile(cameraSpec) : tumCameraByName(cameraSpec);
		if (!camera_.sizeGiven)
		{
			// A camera file without a size: the stream's (as a TUM folder's first image gives it).
			camera_.intrinsics.ncols = static_cast<uint32_t>(cm.getResolutionX());
			camera_.intrinsics.nrows = static_cast<uint32_t>(cm.getResolutionY());
			camera_.sizeGiven = true;
		}
		if (camera_.intrinsics.ncols != static_cast<uint32_t>(cm.getResolutionX()) ||
			camera_.intrinsics.nrows != static_cast<uint32_t>(cm.getResolutionY()))
			throw InputError(cameraSpec, "the camera is " + std::to_string(camera_.intrinsics.ncols) + "x" +
											 std::to_string(camera_.intrinsics.nrows) + ", the stream " + modeText(cm));
	}
	else
	{
		// A pinhole from the colour stream's field of view (what the device reports; a calibration
		// file through --camera is more accurate).
		const double w = cm.getResolutionX(), h = cm.getResolutionY();
		const double hf = impl_->color.getHorizontalFieldOfView(), vf = impl_->color.getVerticalFieldOfView();
		if (!(hf > 0.1 && hf < 3.0 && vf > 0.1 && vf < 3.0))
			throw InputError(file ? o.uri : kWhere,
							 "the device reports no field of view: give intrinsics with --camera");
		camera_.intrinsics.ncols = static_cast<uint32_t>(w);
		camera_.intrinsics.nrows = static_cast<uint32_t>(h);
		camera_.intrinsics.setIntrinsicParamsFromValues(w / (2 * std::tan(hf / 2)), h / (2 * std::tan(vf / 2)),
														(w - 1) / 2, (h - 1) / 2);
		camera_.name = "openni2 field of view";
	}
	camera_.depthScale = dm.getPixelFormat() == openni::PIXEL_FORMAT_DEPTH_1_MM ? 1000.0 : 10000.0;
	camera_.intrinsics.focalLengthMeters = 0;

	if (impl_->depth.start() != openni::STATUS_OK || impl_->color.start() != openni::STATUS_OK)
		throw InputError(file ? o.uri : kWhere,
						 std::string("cannot start the streams: ") + oneLine(openni::OpenNI::getExtendedError()));
	impl_->start = std::chrono::steady_clock::now();
	description_ = std::string(dev.getDeviceInfo().getVendor()) + " " + dev.getDeviceInfo().getName() + ", depth " +
				   modeText(dm) + ", colour " + modeText(cm) + (file ? " (recording)" : "");
	timeoutMs_ = static_cast<int>(o.timeoutSeconds * 1000);
	// A file that falls silent has ended (OpenNI2's player may skip its last frames when they are
	// not read in time): a second, not the timeout meant for an unplugged camera.
	if (file) timeoutMs_ = std::min(timeoutMs_, 1000);
}

COpenNI2Source::~COpenNI2Source()
{
	// A frame still held (one without a partner when the stream ended) belongs to its stream's
	// buffers: released before the stream goes, not after it with the members (a clean-clone test
	// run crashed once at the end of a paced .oni playback, where such a frame is left).
	impl_->lastDepth.release();
	impl_->lastColor.release();
	impl_->depth.stop();
	impl_->color.stop();
	impl_->depth.destroy();
	impl_->color.destroy();
	impl_->device.close();
}

bool COpenNI2Source::isFile() const
{
	return impl_->device.isFile();
}

std::size_t COpenNI2Source::sizeHint() const
{
	return impl_->depthFrames > 0 ? static_cast<std::size_t>(impl_->depthFrames) : 0;
}

mrpt::obs::CObservation3DRangeScan::Ptr COpenNI2Source::next()
{
	if (ended_) return nullptr;
	auto& I = *impl_;
	const bool file = isFile();
	// A file whose streams are read to the end has no pair left (OpenNI2's player would wait).
	const auto exhausted = [&](bool depth)
	{
		return file && (depth ? I.depthFrames > 0 && I.depthRead >= I.depthFrames && !I.lastDepth.isValid()
							  : I.colorFrames > 0 && I.colorRead >= I.colorFrames && !I.lastColor.isValid());
	};
	if (exhausted(true) || exhausted(false))
	{
		ended_ = true;
		return nullptr;
	}
	// Read until a depth frame and a colour frame of the same moment are at hand: their times
	// within half a frame period (OpenNI2's depth-colour sync gives close times; a file written by
	// yesslam-oni equal ones; a camera's recording may hold a frame of one stream only). The older
	// of two frames too far apart can have no partner any more: it is counted (skipped()) and the
	// next frame of its stream read.
	const double halfPeriod = 0.5e6 / std::max(1, I.depth.getVideoMode().getFps());  // us
	for (;;)
	{
		if (I.manual)
		{
			// One frame per request from each stream that needs one: nothing is skipped unread.
			for (const bool depth : {true, false})
			{
				openni::VideoFrameRef& slot = depth ? I.lastDepth : I.lastColor;
				if (slot.isValid()) continue;
				if (exhausted(depth) || (depth ? I.depth : I.color).readFrame(&slot) != openni::STATUS_OK)
				{
					ended_ = true;
					return nullptr;
				}
				(depth ? I.depthRead : I.colorRead)++;
			}
		}
		else
		{
			openni::VideoStream* streams[2] = {&I.depth, &I.color};
			int ready = -1;
			if (openni::OpenNI::waitForAnyStream(streams, 2, &ready, timeoutMs_) != openni::STATUS_OK)
			{
				// Silence: a file has ended; a device was unplugged or stopped.
				ended_ = true;
				disconnected_ = !file;
				return nullptr;
			}
			openni::VideoFrameRef& slot = ready == 0 ? I.lastDepth : I.lastColor;
			if (slot.isValid()) unpaired_++;  // replaced before a partner came
			(ready == 0 ? I.depth : I.color).readFrame(&slot);
			(ready == 0 ? I.depthRead : I.colorRead)++;
		}
		if (!I.lastDepth.isValid() || !I.lastColor.isValid()) continue;
		const double td = static_cast<double>(I.lastDepth.getTimestamp()),
					 tc = static_cast<double>(I.lastColor.getTimestamp());
		if (std::abs(td - tc) <= halfPeriod) break;
		unpaired_++;
		(td < tc ? I.lastDepth : I.lastColor).release();
		if (exhausted(true) || exhausted(false))
		{
			ended_ = true;
			return nullptr;
		}
	}
	const openni::VideoFrameRef& d = I.lastDepth;
	const openni::VideoFrameRef& c = I.lastColor;
	const cv::Mat depth16(d.getHeight(), d.getWidth(), CV_16U, const_cast<void*>(d.getData()),
						  static_cast<std::size_t>(d.getStrideInBytes()));
	const cv::Mat rgb(c.getHeight(), c.getWidth(), CV_8UC3, const_cast<void*>(c.getData()),
					  static_cast<std::size_t>(c.getStrideInBytes()));
	cv::Mat bgr;
	cv::cvtColor(rgb, bgr, cv::COLOR_RGB2BGR);
	// A device's timestamps count from its own start: they are mapped once onto the host's clock
	// (CDeviceClock), so frames keep the device's spacing, not the jitter of their arrival. A
	// recording keeps the times it holds (yesslam-oni writes the source's Unix times, so ground
	// truth and detection files still match).
	const double t =
		file
			? static_cast<double>(d.getTimestamp()) * 1e-6
			: clock_.toHost(d.getTimestamp(),
							std::chrono::duration<double>(std::chrono::system_clock::now().time_since_epoch()).count());
	auto obs = makeRgbdObservation(t, bgr, depth16.clone(), camera_, "OPENNI2");
	// Each pair is used once.
	I.lastDepth.release();
	I.lastColor.release();
	return obs;
}
}  // namespace mrpt_yesslam
