#pragma once
// The keyframe database of place recognition (DBoW2's database as ORB-SLAM2's KeyFrameDatabase
// uses it): an inverted index word -> keyframes holding it, so a query only scores the keyframes
// that share words with the query instead of every keyframe. Kept in step with the map by local
// mapping (added when a keyframe's words are computed, erased when the keyframe is culled).
// Thread-safe: tracking queries it (relocalisation) while local mapping and loop closing change it.
#include <memory>
#include <mutex>
#include <set>
#include <unordered_map>
#include <vector>

#include "mrpt_yesslam/data/TBow.h"
#include "mrpt_yesslam/data/CMapPoint.h"

namespace mrpt_yesslam
{
/** A keyframe sharing words with a query. */
struct TBowCandidate
{
	TKeyFrameId keyFrame = 0;
	std::size_t commonWords = 0;
	double score = 0;       //!< CVocabulary::score with the query (loop detection: S_Loop, eq. 19)
	double groupScore = 0;  //!< groupCandidates: the accumulated score of its covisibility group
};

class CSparseMap;

/** The inverted index. */
class CBowDatabase
{
   public:
	/** `numWords`: the vocabulary's (word ids are below it). */
	explicit CBowDatabase(std::size_t numWords) : index_(numWords) {}

	/** Adds (or replaces) keyframe `id` with its words. */
	void add(TKeyFrameId id, std::shared_ptr<const TBow> bow);
	/** Removes keyframe `id`; false when it was not there. */
	bool erase(TKeyFrameId id);
	/** Number of keyframes held. */
	std::size_t size() const;
	/** The words of keyframe `id` (null when not held). */
	std::shared_ptr<const TBow> bow(TKeyFrameId id) const;

	/** Keyframes sharing words with `query`, except those in `exclude`: ORB-SLAM2's first filter
	 * keeps those sharing at least `minCommonRatio` of the most words any keyframe shares (and at
	 * least `minCommonWords`); each is scored. Sorted by score, best first. */
	std::vector<TBowCandidate> query(const TBowVector& query, const std::set<TKeyFrameId>& exclude = {},
									 double minCommonRatio = 0.8, std::size_t minCommonWords = 1) const;

   private:
	mutable std::mutex mtx_;
	std::vector<std::vector<TKeyFrameId>> index_;  //!< per word, the keyframes holding it
	std::unordered_map<TKeyFrameId, std::shared_ptr<const TBow>> bows_;
};

/** ORB-SLAM2's covisibility grouping of candidates (KeyFrameDatabase::DetectLoopCandidates and
 * DetectRelocalizationCandidates): a single keyframe can look like the query by chance, a place
 * seen from several keyframes cannot. Each candidate's score is accumulated with those of its
 * `neighbours` best covisible keyframes that are candidates too; each group scoring at least
 * `keepRatio` of the best group gives its best-scoring keyframe, once. Sorted by group score. */
std::vector<TBowCandidate> groupCandidates(const std::vector<TBowCandidate>& candidates, const CSparseMap& map,
										   std::size_t neighbours = 10, double keepRatio = 0.75);
}  // namespace mrpt_yesslam
