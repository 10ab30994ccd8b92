#include "mrpt_yesslam/util/AtomicFile.h"

#include <fcntl.h>
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
void makeParentFolder(const std::string& path)
{
	const std::filesystem::path parent = std::filesystem::path(path).parent_path();
	std::error_code ec;
	if (parent.empty() || std::filesystem::is_directory(parent, ec)) return;
	std::filesystem::create_directories(parent, ec);
	if (!std::filesystem::is_directory(parent, ec))
		throw InputError(path, "cannot make its folder" + (ec ? " (" + ec.message() + ")" : std::string()));
}

std::string temporaryPathFor(const std::string& path)
{
	return path + ".tmp." + std::to_string(::getpid());
}

namespace
{
// N for /dev/stdout, /dev/stderr, /dev/fd/N, /proc/self/fd/N and /proc/<our pid>/fd/N; else -1.
int descriptorNamed(const std::string& path)
{
	const std::string p = std::filesystem::path(path).lexically_normal().string();
	if (p == "/dev/stdout") return 1;
	if (p == "/dev/stderr") return 2;
	for (const std::string& prefix :
		 {std::string("/dev/fd/"), std::string("/proc/self/fd/"), "/proc/" + std::to_string(::getpid()) + "/fd/"})
		if (p.size() > prefix.size() && p.compare(0, prefix.size(), prefix) == 0 &&
			p.find_first_not_of("0123456789", prefix.size()) == std::string::npos && p.size() - prefix.size() < 9)
			return std::stoi(p.substr(prefix.size()));
	return -1;
}

// fsync of a file or a folder (a folder: the rename in it); false when it failed. A file that
// cannot be synced (a pipe, /dev/null: EINVAL) has nothing to keep.
bool syncToDisk(const std::string& path)
{
	const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
	if (fd < 0) return false;
	const bool ok = ::fsync(fd) == 0 || errno == EINVAL || errno == EROFS;
	::close(fd);
	return ok;
}
}  // namespace

void appendFileToDescriptor(const std::string& from, int fd, const std::string& path)
{
	std::ifstream in(from, std::ios::binary);
	if (!in) throw InputError(path, "cannot read back what was written for it");
	std::fflush(stdout);
	std::fflush(stderr);
	char buf[65536];
	while (in.read(buf, sizeof(buf)) || in.gcount() > 0)
	{
		const char* p = buf;
		std::size_t left = static_cast<std::size_t>(in.gcount());
		while (left > 0)
		{
			const ssize_t n = ::write(fd, p, left);
			if (n < 0 && errno == EINTR) continue;
			if (n <= 0) throw InputError(path, std::string("write failed (") + std::strerror(errno) + ")");
			p += n, left -= static_cast<std::size_t>(n);
		}
	}
}

std::string makeTemporaryFile()
{
	std::string name = (std::filesystem::temp_directory_path() / "yesslam_out.XXXXXX").string();
	const int fd = ::mkstemp(name.data());
	if (fd < 0) throw InputError(name, std::string("cannot create a temporary file (") + std::strerror(errno) + ")");
	::close(fd);
	return name;
}

TOutputTarget outputTarget(const std::string& path)
{
	namespace fs = std::filesystem;
	TOutputTarget t;
	t.path = path;
	std::error_code ec;
	if (const int fd = descriptorNamed(path); fd >= 0)
	{
		t.fd = fd;
		t.direct = true;
		return t;
	}
	// Follow links (also chains, and relative ones) to the file they name, existing or not.
	for (int hops = 0; hops < 40 && fs::is_symlink(fs::symlink_status(t.path, ec)); hops++)
	{
		// One of our own descriptors: /proc/self/fd/N links to "pipe:[...]" or to the file the
		// shell redirected to; either way only the descriptor itself writes after what is there.
		const int fd = descriptorNamed(t.path);
		if (fd >= 0)
		{
			t.fd = fd;
			t.direct = true;
			return t;
		}
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
	if (target.fd >= 0)
	{
		// Made in a temporary file (the writers take a path), then appended to the descriptor.
		const std::string tmp = makeTemporaryFile();
		try
		{
			writer(tmp);
			appendFileToDescriptor(tmp, target.fd, path);
		}
		catch (...)
		{
			std::remove(tmp.c_str());
			throw;
		}
		std::remove(tmp.c_str());
		return;
	}
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

void writeFileAtomically(const std::string& path, const void* data, std::size_t size, bool durable)
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
			f.close();
			if (!f) throw InputError(path, "write failed (disk full?)");
			// Only a regular file is synced (opening a FIFO to sync it would wait for a writer).
			if (durable && std::filesystem::is_regular_file(tmp) && !syncToDisk(tmp))
				throw InputError(path, std::string("cannot sync to the disk (") + std::strerror(errno) + ")");
		});
	if (durable)
	{
		const auto dir = std::filesystem::path(outputTarget(path).path).parent_path();
		// The rename; a folder that cannot be synced is no error.
		syncToDisk(dir.empty() ? std::string(".") : dir.string());
	}
}

void writeFileAtomically(const std::string& path, const std::string& content)
{
	writeFileAtomically(path, content.data(), content.size());
}

void writePngAtomically(const std::string& path, const cv::Mat& img, int compression)
{
	std::vector<uchar> buf;
	const std::vector<int> params =
		compression < 0 ? std::vector<int>() : std::vector<int>{cv::IMWRITE_PNG_COMPRESSION, compression};
	if (img.empty() || !cv::imencode(".png", img, buf, params)) throw InputError(path, "cannot encode PNG");
	writeFileAtomically(path, buf.data(), buf.size());
}
void writeImageAtomically(const std::string& path, const cv::Mat& img)
{
	std::string ext = std::filesystem::path(path).extension().string();
	std::transform(ext.begin(), ext.end(), ext.begin(),
				   [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
	if (ext == ".png") return writePngAtomically(path, img);
	if (ext != ".jpg" && ext != ".jpeg") throw InputError(path, "unknown image type '" + ext + "' (use .png or .jpg)");
	std::vector<uchar> buf;
	if (img.empty() || !cv::imencode(".jpg", img, buf, {cv::IMWRITE_JPEG_QUALITY, 92}))
		throw InputError(path, "cannot encode JPEG");
	writeFileAtomically(path, buf.data(), buf.size());
}
}  // namespace mrpt_yesslam
