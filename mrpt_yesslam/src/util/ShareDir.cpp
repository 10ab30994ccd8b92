#include "mrpt_yesslam/util/ShareDir.h"

#include <dlfcn.h>
#include <link.h>

#include <cstdlib>
#include <filesystem>
#include <mutex>

namespace mrpt_yesslam
{
namespace
{
std::mutex programDirMtx;
std::string programDir;  // setShareDir's folder

// The file this function was loaded from: libmrpt_yesslam.so when the library is shared, else the
// executable it was linked into. For the executable dladdr names argv[0] (a bare name when run
// through PATH), so the executable's own path comes from /proc/self/exe; the main program's link
// map has an empty name.
std::filesystem::path binaryHoldingTheLibrary()
{
	Dl_info info{};
	link_map* lm = nullptr;
	if (dladdr1(reinterpret_cast<void*>(&shareDir), &info, reinterpret_cast<void**>(&lm), RTLD_DL_LINKMAP) && lm &&
		lm->l_name && *lm->l_name)
	{
		std::error_code ec;
		const auto p = std::filesystem::canonical(lm->l_name, ec);
		if (!ec) return p;
	}
	std::error_code ec;
	return std::filesystem::read_symlink("/proc/self/exe", ec);
}
}  // namespace

void setShareDir(const std::string& dir)
{
	std::lock_guard<std::mutex> lk(programDirMtx);
	programDir = dir;
}

std::string shareDir()
{
	namespace fs = std::filesystem;
	std::error_code ec;
	if (const char* env = std::getenv("YESSLAM_SHARE_DIR"); env && *env && fs::is_directory(env, ec)) return env;
	{
		std::lock_guard<std::mutex> lk(programDirMtx);
		if (!programDir.empty() && fs::is_directory(programDir, ec)) return programDir;
	}
	// bin/yesslam and lib/x86_64-linux-gnu/libmrpt_yesslam.so of an install; rawlog_tools/ and
	// tests/<stage>/ of a build tree, whose share/mrpt_yesslam is a link CMake makes.
	fs::path dir = binaryHoldingTheLibrary().parent_path();
	for (int up = 0; up < 4 && !dir.empty(); up++, dir = dir.parent_path())
	{
		const fs::path candidate = dir / "share" / "mrpt_yesslam";
		if (fs::is_directory(candidate, ec)) return candidate.string();
		if (dir == dir.parent_path()) break;
	}
#ifdef YESSLAM_INSTALL_SHARE_DIR
	// A static library linked into a program elsewhere: where `cmake --install` puts the files.
	if (fs::is_directory(YESSLAM_INSTALL_SHARE_DIR, ec)) return YESSLAM_INSTALL_SHARE_DIR;
#endif
	return {};
}
}  // namespace mrpt_yesslam
