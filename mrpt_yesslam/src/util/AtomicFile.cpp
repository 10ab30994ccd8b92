#include "mrpt_yesslam/util/AtomicFile.h"

#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <opencv2/imgcodecs.hpp>

#include "mrpt_yesslam/util/Error.h"

namespace mrpt_yesslam
{
std::string temporaryPathFor(const std::string& path) { return path + ".tmp." + std::to_string(::getpid()); }

TOutputTarget outputTarget(const std::string& path)
{
	namespace fs = std::filesystem;
	TOutputTarget t;
	t.path = path;
	std::error_code ec;
	// Follow links (also chains, and relative ones) to the file they name, existing or not.
	for (int hops = 0; hops < 40 && fs::is_symlink(fs::symlink_status(t.path, ec)); hops++)
	{
		const fs::path target = fs::read_symlink(t.path, ec);
		if (ec) break;
		t.path = (target.is_absolute() ? target : fs::path(t.path).parent_path() / target).lexically_normal().string();
	}
	const fs::file_status st = fs::status(t.path, ec);
	if (fs::is_directory(st)) throw InputError(path, "is a directory, not a file");
	t.direct = fs::exists(st) && !fs::is_regular_file(st);
	return t;
}

void writeFileAtomically(const std::string& path, const std::function<void(const std::string&)>& writer)
{
	const TOutputTarget target = outputTarget(path);
	if (target.direct)
	{
		writer(target.path);  // a device or pipe: nothing to replace, nothing half-written to hide
		return;
	}
	const std::string tmp = temporaryPathFor(target.path);
	try
	{
		writer(tmp);
	}
	catch (...)
	{
		std::remove(tmp.c_str());
		throw;
	}
	if (std::rename(tmp.c_str(), target.path.c_str()) != 0)
	{
		const std::string why = std::strerror(errno);
		std::remove(tmp.c_str());
		throw InputError(path, "cannot write file (" + why + ")");
	}
}

void writeFileAtomically(const std::string& path, const void* data, std::size_t size)
{
	writeFileAtomically(
		path,
		[&](const std::string& tmp)
		{
			std::ofstream f(tmp, std::ios::binary | std::ios::trunc);
			if (!f) throw InputError(path, std::string("cannot open for writing (") + std::strerror(errno) + ")");
			f.write(static_cast<const char*>(data), static_cast<std::streamsize>(size));
			f.flush();
			if (!f) throw InputError(path, "write failed (disk full?)");
		});
}

void writeFileAtomically(const std::string& path, const std::string& content) { writeFileAtomically(path, content.data(), content.size()); }

void writePngAtomically(const std::string& path, const cv::Mat& img, int compression)
{
	std::vector<uchar> buf;
	const std::vector<int> params = compression < 0 ? std::vector<int>() : std::vector<int>{cv::IMWRITE_PNG_COMPRESSION, compression};
	if (img.empty() || !cv::imencode(".png", img, buf, params)) throw InputError(path, "cannot encode PNG");
	writeFileAtomically(path, buf.data(), buf.size());
}
void writeImageAtomically(const std::string& path, const cv::Mat& img)
{
	std::string ext = std::filesystem::path(path).extension().string();
	std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
	if (ext == ".png") return writePngAtomically(path, img);
	if (ext != ".jpg" && ext != ".jpeg") throw InputError(path, "unknown image type '" + ext + "' (use .png or .jpg)");
	std::vector<uchar> buf;
	if (img.empty() || !cv::imencode(".jpg", img, buf, {cv::IMWRITE_JPEG_QUALITY, 92})) throw InputError(path, "cannot encode JPEG");
	writeFileAtomically(path, buf.data(), buf.size());
}
}  // namespace mrpt_yesslam
