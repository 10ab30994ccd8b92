#pragma once
// The image paths a TUM list file (rgb.txt, depth.txt) of a folder names, for the benches that read
// a folder's frames themselves.
#include <cstdio>
#include <exception>
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

/** The colour and depth images FOLDER's rgb.txt and depth.txt list; false, with "TOOL: error: ..."
 * on stderr, when either list is missing or bad or rgb.txt lists nothing. */
inline bool listFolderImages(const char* tool, const std::string& folder, std::vector<std::string>& rgb,
							 std::vector<std::string>& depth)
{
	try
	{
		rgb = listedImages(folder, "rgb.txt");
		depth = listedImages(folder, "depth.txt");
	}
	catch (const std::exception& e)
	{
		std::fprintf(stderr, "%s: error: %s\n", tool, e.what());
		return false;
	}
	if (rgb.empty()) std::fprintf(stderr, "%s: error: %s/rgb.txt lists no images\n", tool, folder.c_str());
	return !rgb.empty();
}
}  // namespace yesslam_bench
