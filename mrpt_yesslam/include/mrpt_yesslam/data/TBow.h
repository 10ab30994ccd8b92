#pragma once
// Bag-of-words representations of an image (CVocabulary computes them; keyframes keep theirs).
#include <cstdint>
#include <map>
#include <utility>
#include <vector>

namespace mrpt_yesslam
{
/** A bag-of-words vector: (word id, TF-IDF weight) sorted by word, weights summing to 1. */
using TBowVector = std::vector<std::pair<std::uint32_t, float>>;
/** Direct index (DBoW2's FeatureVector): vocabulary node at a chosen level -> indices of the
 * descriptors under it, so matching between two images only compares descriptors in one node. */
using TFeatureVector = std::map<std::uint32_t, std::vector<std::uint32_t>>;

/** The words of one keyframe: its BoW vector and its direct index (static keypoints only). */
struct TBow
{
	TBowVector words;
	TFeatureVector direct;
};
}  // namespace mrpt_yesslam
