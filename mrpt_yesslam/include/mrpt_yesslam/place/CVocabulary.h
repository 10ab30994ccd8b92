#pragma once
// A visual vocabulary of ORB descriptors for place recognition (loop detection, relocalisation),
// as DBoW2 builds it for ORB-SLAM2: a tree of k-means clusters of binary descriptors, L levels deep,
// whose leaves are the words, with TF-IDF weights. Centroids are bitwise majorities of their
// members (k-majority, Grana et al. 2013: the binary analogue of a mean under Hamming distance),
// seeded by k-means++ as DBoW2 does.
//
// Unlike DBoW2's text vocabularies (ORB-SLAM2 spends 10+ s parsing ORBvoc.txt), ours is a flat
// binary file: the tree is stored breadth first with each node's children contiguous, so loading
// is a handful of reads and a checksum, a few milliseconds for 10^5 words.
#include <array>
#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <opencv2/core.hpp>
#include <string>
#include <utility>
#include <vector>

#include "mrpt_yesslam/data/TBow.h"
#include "mrpt_yesslam/feature/COrbExtractor.h"

namespace mrpt_yesslam
{
/** The vocabulary tree. Immutable once built; safe to share between threads. */
class CVocabulary
{
   public:
	/** How to build a vocabulary. */
	struct TTrainOptions
	{
		int branching = 10;      //!< k: children per node
		int levels = 5;          //!< L: depth of the tree; up to k^L words
		int maxIterations = 10;  //!< k-majority iterations per node (stops early when stable)
		std::uint64_t seed = 1;  //!< k-means++ seeding; the same data and seed give the same tree
		int threads = 0;         //!< worker threads for the top-level subtrees (0 = hardware concurrency)
	};

	/** Format version of the binary file; load() refuses newer ones. */
	static constexpr std::uint32_t kFileVersion = 1;

	/** Trains from the ORB descriptors of training images (one CV_8U matrix of 32-byte rows per
	 * image: the IDF weights count images). `progress(doneSubtrees, totalSubtrees)` may be empty.
	 * Throws InputError for invalid options or no descriptors. */
	static CVocabulary train(const std::vector<cv::Mat>& descriptorsPerImage, const TTrainOptions& opts,
							 const std::function<void(std::size_t, std::size_t)>& progress = {});

	/** Writes the vocabulary atomically (binary, versioned, checksummed); `description` is free text
	 * kept in the file (how it was trained). Throws InputError naming the file on failure. */
	void save(const std::string& path) const;
	/** Reads what save() wrote; throws InputError naming the file for a missing, truncated,
	 * corrupt (checksum) or foreign file. */
	static CVocabulary load(const std::string& path);

	/** Number of words (leaves). */
	std::size_t numWords() const { return idf_.size(); }
	/** Number of tree nodes, root included. */
	std::size_t numNodes() const { return desc_.size(); }
	int branching() const { return k_; }
	int levels() const { return levels_; }
	/** Number of images the vocabulary was trained on. */
	std::uint64_t numTrainingImages() const { return trainingImages_; }
	/** Free text describing the training (set before save()). */
	const std::string& description() const { return description_; }
	void setDescription(const std::string& d) { description_ = d; }
	/** A checksum of the tree and the weights (not of the description): two vocabularies with the
	 * same fingerprint give every descriptor the same word. Saved maps record it, since their words
	 * and BoW vectors mean nothing under another vocabulary. */
	std::uint64_t fingerprint() const;
	/** IDF weight of a word: log(N / n_i) over the training images. */
	float idf(std::uint32_t word) const { return idf_.at(word); }

	/** The word of one 32-byte descriptor; with `node`, also the node at depth `nodeLevel` on its
	 * path (the leaf itself when the path is shorter). */
	std::uint32_t word(const std::uint8_t* descriptor, std::uint32_t* node = nullptr, int nodeLevel = 0) const;
	/** The BoW vector of the rows of `descriptors` for which `use` is true (all when `use` is
	 * empty); with `direct`, also the direct index at depth `directLevel` (DBoW2 counts levels up
	 * from the leaves; ORB-SLAM2's levelsUp = 4 of 6 is depth 2 here). */
	void transform(const cv::Mat& descriptors, TBowVector& bow, TFeatureVector* direct = nullptr, int directLevel = 2,
				   const std::vector<bool>& use = {}) const;
	/** The words of a frame's static keypoints (not dynamic, not uncertain): people in view must not
	 * make two places look alike or one place look different (the paper's point in section 2.4). */
	std::shared_ptr<const TBow> bowOf(const TFeatures& features, int directLevel = 2) const;
	/** The shipped vocabulary's path (share/mrpt_yesslam/vocabulary/orb_k10_L5.yvoc); empty when the
	 * share folder is not found. */
	static std::string shippedPath();
	/** DBoW2's L1 score of two BoW vectors, 1 - |a - b|_1 / 2, in [0, 1] (1 = same words in the same
	 * proportions). The paper's eq. 18 writes the same sum over shared words with a factor 2 where
	 * DBoW2 has 1/2; with 2 it would not stay in [0, 1] as its table 6 does, so DBoW2's is used. */
	static double score(const TBowVector& a, const TBowVector& b);

   private:
	struct TTreeNode;
	int k_ = 0, levels_ = 0;
	std::uint64_t trainingImages_ = 0;
	std::string description_;
	/** Per node (breadth first, root = 0): its centroid, first child (children are contiguous),
	 * number of children (0 = leaf) and word id (leaves only). */
	std::vector<std::array<std::uint64_t, 4>> desc_;
	std::vector<std::uint32_t> firstChild_;
	std::vector<std::uint8_t> numChildren_;
	std::vector<std::uint32_t> wordOfNode_;
	std::vector<float> idf_;  //!< per word
};
}  // namespace mrpt_yesslam
