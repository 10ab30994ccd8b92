#pragma once
// Bayesian label fusion of one 3D cell over the keyframes that see it (paper eq. 27-29):
// p(L | x_0..t) = p^(L | x_t) p(L | x_0..t-1) / Z_t, with a uniform prior over the classes.
//
// The measurement model (the paper leaves it open; we follow SemanticFusion, McCormac et al. 2017,
// which multiplies per-pixel class probabilities, with a detector in place of a CNN): a pixel
// labelled with class c by a detection of confidence s gives p^(c) = p(s) and shares 1 - p(s)
// evenly among the other classes; an unlabelled pixel ("no detected object": background) gives
// the background class p^(0) = backgroundProb in the same way. The state is kept in log space and
// sparsely: every class never observed has the same log probability (`base`), so a cell stores
// only that and the extra log evidence of the few classes it was seen as.
#include <cstdint>
#include <utility>
#include <vector>

namespace mrpt_yesslam
{
/** A label as the dense map stores it: 0 = background (no detected object), c + 1 = COCO class c. */
using TSemLabel = std::uint8_t;

/** The class distribution of one cell, in log space, sparse (see the file comment). */
struct TLabelBelief
{
	double base = 0;                                  //!< log-evidence of every class never observed
	std::vector<std::pair<TSemLabel, double>> extra;  //!< (label, log-evidence above `base`)
	std::uint32_t observations = 0;

	/** Eq. 29 with one measurement: the pixel's label `l` with probability `p` (0.5 < p < 1 is
	 * evidence for l), among `numLabels` labels (background included). */
	void observe(TSemLabel l, double p, int numLabels);
	/** Adds another cell's evidence (both from independent measurements). */
	void merge(const TLabelBelief& o);
	/** The most likely label and its normalised probability (eq. 27's 1/Z_t). With no
	 * observation: background, 1 / numLabels. */
	std::pair<TSemLabel, double> best(int numLabels) const;
	/** The normalised probability of label `l`. */
	double probability(TSemLabel l, int numLabels) const;
};
}  // namespace mrpt_yesslam
