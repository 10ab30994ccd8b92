#include "mrpt_yesslam/io/COniWriter.h"

#include <algorithm>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <optional>
#include <opencv2/imgproc.hpp>

#include "mrpt_yesslam/io/CTumFolderSource.h"
#include "mrpt_yesslam/io/RgbdCamera.h"
#include "mrpt_yesslam/io/RgbdObservation.h"
#include "mrpt_yesslam/util/TextParsing.h"
#include "mrpt_yesslam/util/AtomicFile.h"
#include "mrpt_yesslam/util/Error.h"

namespace fs = std::filesystem;

namespace mrpt_yesslam
{
namespace
{
// The ONI container (OpenNI 1.x/2.x, file version 1.0.1.0), little-endian and packed: a 24-byte
// file header, then records of a 28-byte header ("NIR\0", type, node, size of header + fields,
// payload size, position of the record this one supersedes) followed by fields and payload.
enum : std::uint32_t
{
	kIntProperty = 0x03,
	kGeneralProperty = 0x06,
	kNodeRemoved = 0x07,
	kNodeDataBegin = 0x08,
	kNodeStateReady = 0x09,
	kNewData = 0x0A,
	kEnd = 0x0B,
	kNodeAdded = 0x0D,
	kSeekTable = 0x0E
};
constexpr std::uint32_t kRecordMagic = 0x0052494E;  // "NIR\0"
constexpr std::uint32_t kNodeDepth = 2, kNodeImage = 3;
constexpr std::uint32_t codecId(char a, char b, char c, char d)
{
	return static_cast<std::uint32_t>(static_cast<unsigned char>(a)) |
		   static_cast<std::uint32_t>(static_cast<unsigned char>(b)) << 8 |
		   static_cast<std::uint32_t>(static_cast<unsigned char>(c)) << 16 |
		   static_cast<std::uint32_t>(static_cast<unsigned char>(d)) << 24;
}
constexpr std::uint32_t kCodecNone = codecId('N', 'O', 'N', 'E');
constexpr std::size_t kHeaderSize = 28, kFileHeaderSize = 24;
// OpenNI2 pixel formats (OniCEnums.h) and their OpenNI 1.x names (xnPixelFormat).
constexpr std::uint64_t kOniDepth1mm = 100, kOniDepth100um = 101, kOniRgb888 = 200;
constexpr std::uint64_t kXnRgb24 = 1, kXnGray16 = 4;

// Little-endian field bytes.
struct TBytes
{
	std::string b;
	template <class T>
	TBytes& put(T v)
	{
		static_assert(std::is_integral_v<T> || std::is_floating_point_v<T>);
		char raw[sizeof(T)];
		std::memcpy(raw, &v, sizeof(T));  // the machines are little-endian, as the format
		b.append(raw, sizeof(T));
		return *this;
	}
	// A string field: its length with the terminating zero (u32), then its bytes and the zero.
	TBytes& str(const std::string& s)
	{
		put(static_cast<std::uint32_t>(s.size() + 1));
		b.append(s);
		b.push_back('\0');
		return *this;
	}
	TBytes& raw(const void* p, std::size_t n)
	{
		b.append(static_cast<const char*>(p), n);
		return *this;
	}
};
}  // namespace

COniWriter::COniWriter(const std::string& path) : path_(path), tmp_(temporaryPathFor(path))
{
	out_.open(tmp_, std::ios::binary | std::ios::trunc);
	if (!out_) throw InputError(path, "cannot create the file (does its folder exist and is it writable?)");
	depth_.id = 1;
	depth_.depth = true;
	color_.id = 2;
}

COniWriter::~COniWriter()
{
	if (!finished_)
	{
		out_.close();
		std::error_code ec;
		fs::remove(tmp_, ec);
	}
}

void COniWriter::writeRecord(std::uint32_t type, std::uint32_t node, std::uint64_t undo, const std::string& fields,
							 const void* payload, std::size_t payloadSize)
{
	TBytes h;
	h.put(kRecordMagic)
		.put(type)
		.put(node)
		.put(static_cast<std::uint32_t>(kHeaderSize + fields.size()))
		.put(static_cast<std::uint32_t>(payloadSize))
		.put(undo);
	out_.write(h.b.data(), static_cast<std::streamsize>(h.b.size()));
	out_.write(fields.data(), static_cast<std::streamsize>(fields.size()));
	if (payloadSize) out_.write(static_cast<const char*>(payload), static_cast<std::streamsize>(payloadSize));
	if (!out_) throw InputError(path_, "write failed (disk full?)");
}

void COniWriter::nodeAdded(const TNode& n, std::uint32_t frames, std::uint64_t minStamp, std::uint64_t maxStamp,
						   std::uint64_t seekTable)
{
	TBytes f;
	f.str(n.depth ? "Depth" : "Image")
		.put(n.depth ? kNodeDepth : kNodeImage)
		.put(kCodecNone)
		.put(frames)
		.put(minStamp)
		.put(maxStamp)
		.put(seekTable);
	writeRecord(kNodeAdded, n.id, 0, f.b, nullptr, 0);
}

void COniWriter::property(TNode& n, const std::string& name, const void* data, std::size_t size, bool integer)
{
	// Each property record points back at the previous property record of its node (as OpenNI2's
	// recorder does for the same name; the player only uses it to undo while seeking).
	const std::uint64_t pos = static_cast<std::uint64_t>(out_.tellp());
	TBytes f;
	f.str(name).put(static_cast<std::uint32_t>(size)).raw(data, size);
	writeRecord(integer ? kIntProperty : kGeneralProperty, n.id, 0, f.b, nullptr, 0);
	n.lastPropPos = pos;
}

void COniWriter::newData(TNode& n, std::uint64_t stamp, const void* data, std::size_t size)
{
	const std::uint64_t pos = static_cast<std::uint64_t>(out_.tellp());
	TBytes f;
	f.put(stamp).put(static_cast<std::uint32_t>(n.stamps.size() + 1));  // frame ids start at 1
	writeRecord(kNewData, n.id, n.lastDataPos, f.b, data, size);
	n.lastDataPos = pos;
	n.stamps.push_back(stamp);
	n.positions.push_back(pos);
}

void COniWriter::start(const mrpt::obs::CObservation3DRangeScan& first)
{
	width_ = static_cast<int>(first.rangeImage.cols());
	height_ = static_cast<int>(first.rangeImage.rows());
	// OpenNI2 depth units: 100 um when the source's unit is a whole multiple of it (exact), else mm.
	const double per100um = static_cast<double>(first.rangeUnits) / 1e-4;
	unit100um_ = std::abs(per100um - std::round(per100um)) < 1e-3 && std::round(per100um) >= 1;
	depthFactor_ = unit100um_ ? std::round(per100um) : static_cast<double>(first.rangeUnits) / 1e-3;

	TBytes fh;
	fh.raw("NI10", 4)
		.put(std::uint8_t{1})
		.put(std::uint8_t{0})
		.put(std::uint16_t{1})
		.put(std::uint32_t{0})
		.put(~std::uint64_t{0})
		.put(std::uint32_t{2});
	out_.write(fh.b.data(), static_cast<std::streamsize>(fh.b.size()));

	const auto& cam = first.cameraParamsIntensity;
	const double hfov = 2 * std::atan(width_ / (2 * cam.fx())), vfov = 2 * std::atan(height_ / (2 * cam.fy()));
	for (TNode* n : {&depth_, &color_})
	{
		n->addedPos = static_cast<std::uint64_t>(out_.tellp());
		nodeAdded(*n, ~std::uint32_t{0}, 0, ~std::uint64_t{0}, 0);
		char device[256] = {0};
		std::strncpy(device, "yesslam-oni", sizeof(device) - 1);
		property(*n, "oniOriginalDevice", device, sizeof(device), false);
		const std::uint64_t frameSize = static_cast<std::uint64_t>(width_) * height_ * (n->depth ? 2 : 3);
		property(*n, "oniRequiredFrameSize", &frameSize, 8, true);
		const std::uint64_t yes = 1;
		property(*n, "xnIsGenerating", &yes, 8, true);
		if (n->depth)
		{
			const std::uint64_t maxDepth = 65535;
			property(*n, "xnDeviceMaxDepth", &maxDepth, 8, true);
		}
		const std::uint64_t one = 1;
		property(*n, "xnSupportedMapOutputModesCount", &one, 8, true);
		const std::uint32_t mode[3] = {static_cast<std::uint32_t>(width_), static_cast<std::uint32_t>(height_), 30};
		// The frame rate is the mode's last field: rewritten by finish() from the frames' times.
		property(*n, "xnSupportedMapOutputModes", mode, sizeof(mode), false);
		n->fpsPositions.push_back(static_cast<std::uint64_t>(out_.tellp()) - 4);
		property(*n, "xnMapOutputMode", mode, sizeof(mode), false);
		n->fpsPositions.push_back(static_cast<std::uint64_t>(out_.tellp()) - 4);
		const std::uint32_t supported = n->depth ? 8u : 1u;  // bit 3: 16-bit grey; bit 0: RGB24
		property(*n, "xnSupportedPixelFormats", &supported, 4, false);
		const std::uint64_t xnFormat = n->depth ? kXnGray16 : kXnRgb24;
		property(*n, "xnPixelFormat", &xnFormat, 8, true);
		const std::uint64_t oniFormat = n->depth ? (unit100um_ ? kOniDepth100um : kOniDepth1mm) : kOniRgb888;
		property(*n, "oniPixelFormat", &oniFormat, 8, true);
		const double fov[2] = {hfov, vfov};
		property(*n, "xnFOV", fov, sizeof(fov), false);
		// Cropping (off): OpenNI2's player drops every frame of a stream without this property.
		const std::uint64_t canCrop = 1;
		property(*n, "Cropping", &canCrop, 8, true);
		unsigned char cropping[12] = {0};  // enabled (4 bytes), x, y, width, height (2 bytes each)
		property(*n, "xnCropping", cropping, sizeof(cropping), false);
	}
	for (TNode* n : {&depth_, &color_})
	{
		writeRecord(kNodeStateReady, n->id, 0, {}, nullptr, 0);
		TBytes f;
		f.put(~std::uint32_t{0}).put(~std::uint64_t{0});
		writeRecord(kNodeDataBegin, n->id, 0, f.b, nullptr, 0);
	}
	started_ = true;
}

void COniWriter::write(const mrpt::obs::CObservation3DRangeScan& obs, const TOniStreams& streams)
{
	if (!streams.depth && !streams.colour) return;
	if (!(streams.colourDelay >= 0 && streams.colourDelay < 1))
		throw InputError(path_, "colour delay must be in [0, 1) s");
	validateRgbdObservation(obs, path_);
	if (!started_)
	{
		firstUnits_ = obs.rangeUnits;
		start(obs);
	}
	// The depth factor was chosen from the first frame: another unit would be stored wrongly scaled.
	if (obs.rangeUnits != firstUnits_)
		throw InputError(path_, "frame " + std::to_string(frames_) + " has depth in units of " +
									std::to_string(obs.rangeUnits) + " m, the recording " +
									std::to_string(firstUnits_) + " m (one recording has one depth unit)");
	if (obs.rangeImage.cols() != width_ || obs.rangeImage.rows() != height_)
		throw InputError(path_, "frame " + std::to_string(frames_) + " is " + std::to_string(obs.rangeImage.cols()) +
									"x" + std::to_string(obs.rangeImage.rows()) + ", the recording " +
									std::to_string(width_) + "x" + std::to_string(height_));
	const double t = observationTime(obs);
	if (!(t >= 0)) throw InputError(path_, "frame " + std::to_string(frames_) + " has a negative time");
	const std::uint64_t stamp = static_cast<std::uint64_t>(std::llround(t * 1e6));
	const std::uint64_t colourStamp = stamp + static_cast<std::uint64_t>(std::llround(streams.colourDelay * 1e6));
	if ((streams.depth && !depth_.stamps.empty() && stamp <= depth_.stamps.back()) ||
		(streams.colour && !color_.stamps.empty() && colourStamp <= color_.stamps.back()))
		throw InputError(path_, "frame " + std::to_string(frames_) +
									" is not later than the one before (OpenNI2 plays frames in time order)");

	depthBuf_.resize(static_cast<std::size_t>(width_) * height_);
	for (int r = 0; r < height_; r++)
		for (int c = 0; c < width_; c++)
		{
			const double v = std::round(obs.rangeImage(r, c) * depthFactor_);
			std::uint16_t& d = depthBuf_[static_cast<std::size_t>(r) * width_ + c];
			if (v > 65535)
			{
				d = 0;
				clipped_++;
			}
			else
				d = static_cast<std::uint16_t>(v);
		}
	const cv::Mat& bgr = obs.intensityImage.asCvMatRef();
	cv::Mat rgb(height_, width_, CV_8UC3);
	if (bgr.channels() == 3)
		cv::cvtColor(bgr, rgb, cv::COLOR_BGR2RGB);
	else
		cv::cvtColor(bgr, rgb, cv::COLOR_GRAY2RGB);
	if (streams.depth) newData(depth_, stamp, depthBuf_.data(), depthBuf_.size() * 2);
	if (streams.colour) newData(color_, colourStamp, rgb.data, rgb.total() * 3);
	frames_++;
}

std::uintmax_t COniWriter::finish()
{
	if (frames_ == 0) throw InputError(path_, "no frame to write");
	if (depth_.stamps.empty() || color_.stamps.empty())
		throw InputError(path_, "no frame of one of the streams (depth and colour are both needed)");
	for (TNode* n : {&depth_, &color_})
	{
		writeRecord(kNodeRemoved, n->id, n->addedPos, {}, nullptr, 0);
		const std::uint64_t seekPos = static_cast<std::uint64_t>(out_.tellp());
		// One entry per frame (time, configuration 0, record position) after an empty one for
		// frame 0: frame ids start at 1.
		TBytes table;
		table.put(std::uint64_t{0}).put(std::uint32_t{0}).put(std::uint64_t{0});
		for (std::size_t i = 0; i < n->stamps.size(); i++)
			table.put(n->stamps[i]).put(std::uint32_t{0}).put(n->positions[i]);
		writeRecord(kSeekTable, n->id, 0, {}, table.b.data(), table.b.size());
		// The node record again, now with its frame count, time range and seek table.
		const auto end = out_.tellp();
		out_.seekp(static_cast<std::streamoff>(n->addedPos));
		nodeAdded(*n, static_cast<std::uint32_t>(n->stamps.size()), n->stamps.front(), n->stamps.back(), seekPos);
		out_.seekp(end);
	}
	writeRecord(kEnd, 0, 0, {}, nullptr, 0);
	// The input's frame rate (OpenNI2 applications pace playback and pick modes by it; 30 was
	// written for every input).
	std::uint32_t fps = 30;
	if (depth_.stamps.size() >= 2)
	{
		std::vector<std::uint64_t> dt;
		for (std::size_t i = 1; i < depth_.stamps.size(); i++) dt.push_back(depth_.stamps[i] - depth_.stamps[i - 1]);
		std::nth_element(dt.begin(), dt.begin() + static_cast<std::ptrdiff_t>(dt.size() / 2), dt.end());
		const double median = static_cast<double>(dt[dt.size() / 2]);
		if (median > 0) fps = static_cast<std::uint32_t>(std::clamp(std::lround(1e6 / median), 1L, 1000L));
	}
	for (TNode* n : {&depth_, &color_})
		for (const std::uint64_t pos : n->fpsPositions)
		{
			out_.seekp(static_cast<std::streamoff>(pos));
			out_.write(reinterpret_cast<const char*>(&fps), 4);
		}
	fps_ = fps;
	// The header's largest time stamp (after the magic and the 8-byte version).
	out_.seekp(12);
	TBytes maxT;
	maxT.put(std::max(depth_.stamps.back(), color_.stamps.back()));
	out_.write(maxT.b.data(), 8);
	out_.close();
	if (!out_) throw InputError(path_, "write failed (disk full?)");
	std::error_code ec;
	fs::rename(tmp_, path_, ec);
	if (ec) throw InputError(path_, "cannot move the finished file into place: " + ec.message());
	finished_ = true;
	return fs::file_size(path_);
}

TOniConversion convertToOni(const std::string& input, const std::string& output,
							const CInputSource::TOptions& inputOptions, std::size_t maxFrames,
							const std::function<void(std::size_t, std::size_t)>& progress,
							const std::function<bool()>& cancel)
{
	TOniConversion r;
	auto src = openInputSource(input, inputOptions);
	const fs::path outDir = fs::path(output).parent_path();
	if (!outDir.empty())
	{
		std::error_code ec;
		fs::create_directories(outDir, ec);
		if (!fs::is_directory(outDir))
			throw InputError(output, "cannot create its folder" + (ec ? " (" + ec.message() + ")" : std::string()));
	}
	COniWriter w(output);
	std::optional<TRgbdCamera> camera;  // the input's, from its first frame (a TUM folder: its camera model)
	while (!(maxFrames && r.frames >= maxFrames))
	{
		if (cancel && cancel())
		{
			r.interrupted = true;
			break;
		}
		auto obs = src->next();
		if (!obs) break;
		w.write(*obs);
		// A TUM folder's camera model once its first frame was read (it gives the size a
		// calibration without one lacks); a rawlog's from its frames.
		if (const auto* tum = dynamic_cast<const CTumFolderSource*>(src.get()); tum && !camera) camera = tum->camera();
		if (!camera)
		{
			camera = TRgbdCamera();
			camera->intrinsics = obs->cameraParamsIntensity;
			camera->name = input;
			if (const auto known = knownReadout(input, inputOptions))
			{
				camera->readout = known->seconds;
				camera->readoutSource = known->source;
			}
		}
		const double t = observationTime(*obs);
		if (r.frames == 0) r.tFirst = t;
		r.tLast = t;
		r.frames++;
		if (progress)
		{
			// The total this conversion will write: at most --max-frames (0 = unknown).
			std::size_t total = src->sizeHint();
			if (maxFrames && (total == 0 || total > maxFrames)) total = maxFrames;
			progress(r.frames, total);
		}
	}
	r.bytes = w.finish();
	r.clippedPixels = w.clippedPixels();
	r.depthIn100um = w.depthIn100um();
	if (camera && r.frames > 0)
	{
		r.cameraFile = recordingCameraPath(output);
		writeFileAtomically(r.cameraFile,
							formatCameraFile(*camera, "the camera of " + fs::path(output).filename().string() +
														  " (yesslam-oni, from " + input + ")"));
	}
	const std::string gt = findGroundTruthFor(input);
	if (!gt.empty())
	{
		const fs::path out(output);
		r.groundTruth = (out.parent_path() / (out.stem().string() + "_groundtruth.txt")).string();
		writeFileAtomically(r.groundTruth, readTextFile(gt));
	}
	// The detections that go with the frames: without them a run on the .oni silently falls back to another detector,
	// and a generated walking sequence came out far worse.
	const fs::path in(input);
	const fs::path det = fs::is_directory(in) ? in / "detections.txt" : in.parent_path() / "detections.txt";
	std::error_code ec;
	if (fs::is_regular_file(det, ec))
	{
		const fs::path to = (outDir.empty() ? fs::path(".") : outDir) / "detections.txt";
		const std::string text = readTextFile(det.string());
		if (fs::equivalent(det, to, ec))
			r.detections = to.string();
		else if (fs::exists(to, ec) && readTextFile(to.string()) != text)
			r.detectionsNote = to.string() + " exists and differs from the input's: not replaced";
		else
		{
			writeFileAtomically(to.string(), text);
			r.detections = to.string();
		}
	}
	return r;
}
}  // namespace mrpt_yesslam
