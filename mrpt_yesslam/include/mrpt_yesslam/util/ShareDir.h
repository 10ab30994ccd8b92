#pragma once
// Where the files shipped in share/mrpt_yesslam are at run time (the default detector model).
#include <string>

namespace mrpt_yesslam
{
/** The share/mrpt_yesslam folder: $YESSLAM_SHARE_DIR when set, else the source tree's (builds run
 * from the build tree), else ../share/mrpt_yesslam beside the running executable's folder (an
 * installed copy). Empty when none exists. */
std::string shareDir();
}  // namespace mrpt_yesslam
