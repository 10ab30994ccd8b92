#pragma once
// Procedural textures for the simulator: dense, non-periodic clutter (shapes, lines, glyphs, noise)
// so that ORB finds many distinctive corners, as on a real office's posters, books and screens.
#include <cstdint>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

namespace mrpt_yesslam
{
/** A BGR texture of side `size`, deterministic in `seed`, around a base colour; `density` scales
 * the number of shapes (1 = printed matter everywhere, ~0.2 = a painted wall with a few marks). */
cv::Mat makeClutterTexture(uint32_t seed, int size, const cv::Scalar& base, double density = 1.0);

/** Loads every .png/.jpg of a folder (sorted by name) as textures of side `size`; throws
 * InputError when the folder has none. */
std::vector<cv::Mat> loadPhotoTextures(const std::string& folder, int size);
}  // namespace mrpt_yesslam
