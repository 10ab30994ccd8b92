#include "mrpt_yesslam/io/CTumFolderSource.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <opencv2/imgcodecs.hpp>

#include "mrpt_yesslam/io/Association.h"
#include "mrpt_yesslam/io/PngDecoder.h"
#include "mrpt_yesslam/io/RgbdObservation.h"
#include "mrpt_yesslam/util/TextParsing.h"
#include "mrpt_yesslam/util/Error.h"

namespace fs = std::filesystem;

namespace mrpt_yesslam
{
std::vector<TTumListEntry> readTumFileList(const std::string& path)
{
	return parseTumFileList(readTextFile(path), path);
}

std::vector<TTumListEntry> parseTumFileList(const std::string& text, const std::string& path)
{
	const auto lines = splitLines(text);
	std::vector<TTumListEntry> out;
	for (std::size_t i = 0; i < lines.size(); i++)
	{
		if (isCommentOrBlank(lines[i])) continue;
		const auto f = splitFields(lines[i]);
		// Some copies of the TUM lists have the header "timestamp filename" without its '#'.
		if (out.empty() && !f.empty() && f[0] == "timestamp") continue;
		const std::string where = "line " + std::to_string(i + 1) + ": ";
		if (f.size() < 2) throw InputError(path, where + "expected 'timestamp filename'");
		TTumListEntry e;
		if (!parseFiniteDouble(f[0], e.t)) throw InputError(path, where + "'" + f[0] + "' is not a finite timestamp");
		if (!out.empty() && e.t < out.back().t)
			throw InputError(
				path, where + "timestamp " + f[0] + " is earlier than the line before; TUM lists are in time order");
		e.file = f[1];
		out.push_back(std::move(e));
	}
	return out;
}

CTumFolderSource::CTumFolderSource(const std::string& folder, const TOptions& opts) : folder_(folder)
{
	std::error_code ec;
	if (!fs::exists(folder, ec)) throw InputError(folder, "folder not found");
	if (!fs::is_directory(folder, ec)) throw InputError(folder, "not a folder (expected a TUM RGB-D folder)");
	const std::string rgbList = (fs::path(folder) / "rgb.txt").string();
	const std::string depthList = (fs::path(folder) / "depth.txt").string();
	if (!fs::exists(rgbList, ec)) throw InputError(rgbList, "file not found (is this a TUM RGB-D folder?)");
	if (!fs::exists(depthList, ec)) throw InputError(depthList, "file not found (is this a TUM RGB-D folder?)");
	const auto rgb = readTumFileList(rgbList);
	const auto depth = readTumFileList(depthList);
	if (rgb.empty()) throw InputError(rgbList, "lists no images");
	if (depth.empty()) throw InputError(depthList, "lists no images");
	if (!(opts.maxDiff > 0)) throw InputError(folder, "maximum rgb/depth time difference must be positive");

	std::vector<double> tr, td;
	for (const auto& e : rgb) tr.push_back(e.t);
	for (const auto& e : depth) td.push_back(e.t);
	const auto matches = associateTimestamps(tr, td, 0.0, opts.maxDiff);
	if (matches.empty())
		throw InputError(rgbList, "no image has a depth.txt entry within " + std::to_string(opts.maxDiff) + " s (rgb " +
									  std::to_string(tr.front()) + ".." + std::to_string(tr.back()) + ", depth " +
									  std::to_string(td.front()) + ".." + std::to_string(td.back()) + ")");
	for (const auto& [i, j] : matches)
	{
		TTumFrame fr;
		fr.tRgb = rgb[i].t;
		fr.tDepth = depth[j].t;
		fr.rgbPath = (fs::path(folder) / rgb[i].file).string();
		fr.depthPath = (fs::path(folder) / depth[j].file).string();
		frames_.push_back(std::move(fr));
	}
	skipped_ = rgb.size() - matches.size();
	camera_ = resolveTumCamera(opts.camera, folder);
}

std::optional<double> CTumFolderSource::depthTime(double colourTime) const
{
	// frames_ is in colour-time order and never changes after construction (thread-safe to read).
	const auto it = std::lower_bound(frames_.begin(), frames_.end(), colourTime - 1e-5,
									 [](const TTumFrame& f, double t) { return f.tRgb < t; });
	if (it == frames_.end() || std::abs(it->tRgb - colourTime) > 1e-5) return std::nullopt;
	return it->tDepth;
}

mrpt::obs::CObservation3DRangeScan::Ptr CTumFolderSource::next()
{
	if (next_ >= frames_.size()) return nullptr;
	const TTumFrame& fr = frames_[next_++];
	std::error_code ec;
	if (!fs::exists(fr.rgbPath, ec)) throw InputError(fr.rgbPath, "image listed in rgb.txt not found");
	if (!fs::exists(fr.depthPath, ec)) throw InputError(fr.depthPath, "image listed in depth.txt not found");
	const cv::Mat bgr = readImageFile(fr.rgbPath, cv::IMREAD_COLOR, "image");
	const cv::Mat depth = readImageFile(fr.depthPath, cv::IMREAD_UNCHANGED, "depth image");
	if (depth.channels() != 1)
		throw InputError(fr.depthPath, "depth image has " + std::to_string(depth.channels()) + " channels, expected 1");
	if (depth.depth() == CV_8U)
		throw InputError(fr.depthPath, "depth image is 8-bit; TUM depth must be 16-bit (raw / 5000 = metres)");
	if (depth.depth() == CV_32F || depth.depth() == CV_64F)
		throw InputError(
			fr.depthPath,
			"depth image holds floating-point values (metres?); expected 16-bit integers (raw / 5000 = metres)");
	if (depth.depth() != CV_16U) throw InputError(fr.depthPath, "depth image is not 16-bit unsigned");
	if (depth.size() != bgr.size())
		throw InputError(fr.depthPath, "depth image is " + std::to_string(depth.cols) + "x" +
										   std::to_string(depth.rows) + " but its colour image is " +
										   std::to_string(bgr.cols) + "x" + std::to_string(bgr.rows));
	if (!camera_.sizeGiven)
	{
		// A camera file without a size: the images give it (the first one; the rest must agree).
		camera_.intrinsics.ncols = static_cast<std::uint32_t>(bgr.cols);
		camera_.intrinsics.nrows = static_cast<std::uint32_t>(bgr.rows);
		camera_.sizeGiven = true;
		sizeFromImage_ = true;
		const double cx = camera_.intrinsics.cx(), cy = camera_.intrinsics.cy();
		if (!(cx > 0 && cy > 0 && cx < bgr.cols && cy < bgr.rows))
			throw InputError(camera_.name, "principal point (" + std::to_string(cx) + ", " + std::to_string(cy) +
											   ") lies outside the " + std::to_string(bgr.cols) + "x" +
											   std::to_string(bgr.rows) + " images of " + folder_);
	}
	if (static_cast<unsigned>(bgr.cols) != camera_.intrinsics.ncols ||
		static_cast<unsigned>(bgr.rows) != camera_.intrinsics.nrows)
		throw InputError(fr.rgbPath,
						 "image is " + std::to_string(bgr.cols) + "x" + std::to_string(bgr.rows) +
							 (sizeFromImage_ ? " but the first image was " : " but camera '" + camera_.name + "' is ") +
							 std::to_string(camera_.intrinsics.ncols) + "x" + std::to_string(camera_.intrinsics.nrows));
	return makeRgbdObservation(fr.tRgb, bgr, depth, camera_);
}
}  // namespace mrpt_yesslam
