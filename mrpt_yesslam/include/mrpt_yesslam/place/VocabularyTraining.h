#pragma once
// Training a vocabulary from the user's own images (yesslam-vocab): ORB descriptors are extracted
// with the same [ORB] settings as tracking, from photographs, TUM folders and rawlogs, so the words
// are those tracking will later look up.
#include <functional>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "mrpt_yesslam/feature/COrbExtractor.h"
#include "mrpt_yesslam/io/CInputSource.h"
#include "mrpt_yesslam/place/CVocabulary.h"

namespace mrpt_yesslam
{
/** What to train on and how. */
struct TVocabTrainingOptions
{
	/** Image files, folders of images (searched recursively), TUM RGB-D folders (with rgb.txt) and
	 * rawlogs. */
	std::vector<std::string> inputs;
	COrbExtractor::TOptions orb;    //!< the tracking's [ORB] settings
	CInputSource::TOptions source;  //!< [Input]: camera, sensor label
	/** Sequences (TUM folders, rawlogs): every step-th frame; consecutive frames add little. */
	std::size_t step = 5;
	std::size_t maxImagesPerInput = 0;  //!< 0 = all
	CVocabulary::TTrainOptions tree;
};

/** Counts of a training run. */
struct TVocabTrainingSummary
{
	std::size_t images = 0, descriptors = 0;
	double extractSeconds = 0, trainSeconds = 0;
	bool interrupted = false;  //!< stopped while reading: trained on what was read
};

/** The descriptors of every training image (one matrix per image). `progress(imagesRead)` may be
 * empty; `stop()` ends reading early. Throws InputError naming the input for a missing path, an
 * unreadable image or a folder without images. */
std::vector<cv::Mat> collectTrainingDescriptors(const TVocabTrainingOptions& opts,
												const std::function<void(std::size_t)>& progress = {},
												const std::function<bool()>& stop = {});

/** Reads the inputs, trains and returns the vocabulary (its description records the inputs and
 * the ORB settings). */
CVocabulary trainVocabulary(
	const TVocabTrainingOptions& opts, TVocabTrainingSummary* summary = nullptr,
	const std::function<void(const std::string& stage, std::size_t done, std::size_t total)>& progress = {},
	const std::function<bool()>& stop = {});
}  // namespace mrpt_yesslam
