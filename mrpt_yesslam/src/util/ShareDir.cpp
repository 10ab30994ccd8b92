#include "mrpt_yesslam/util/ShareDir.h"

#include <cstdlib>
#include <filesystem>

namespace mrpt_yesslam
{
std::string shareDir()
{
	namespace fs = std::filesystem;
	std::error_code ec;
	if (const char* env = std::getenv("YESSLAM_SHARE_DIR"); env && *env && fs::is_directory(env, ec)) return env;
#ifdef YESSLAM_SOURCE_SHARE_DIR
	if (fs::is_directory(YESSLAM_SOURCE_SHARE_DIR, ec)) return YESSLAM_SOURCE_SHARE_DIR;
#endif
	const fs::path exe = fs::read_symlink("/proc/self/exe", ec);
	if (!ec)
	{
		const fs::path installed = exe.parent_path().parent_path() / "share" / "mrpt_yesslam";
		if (fs::is_directory(installed, ec)) return installed.string();
	}
	return {};
}
}  // namespace mrpt_yesslam
