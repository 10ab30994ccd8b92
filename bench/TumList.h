#pragma once
// The image paths a TUM list file (rgb.txt, depth.txt) of a folder names, for the benches that read
// a folder's frames themselves.
#include <string>
#include <vector>

#include "mrpt_yesslam/io/CTumFolderSource.h"

namespace yesslam_bench
{
/** FOLDER/PATH for each line of FOLDER/LIST, in order; throws InputError for a missing or bad list. */
inline std::vector<std::string> listedImages(const std::string& folder, const std::string& list)
{
	std::vector<std::string> out;
	for (const auto& e : mrpt_yesslam::readTumFileList(folder + "/" + list)) out.push_back(folder + "/" + e.file);
	return out;
}
}  // namespace yesslam_bench
