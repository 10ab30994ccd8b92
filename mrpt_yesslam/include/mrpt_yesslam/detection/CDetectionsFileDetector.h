#pragma once
// Detections computed offline (by yesslam-detect, yesslam-sim, or any detector a user runs, e.g. the
// official YOLOv7 in PyTorch), read from a text file and matched to frames by timestamp. Format,
// one detection per line, '#' comments:
//   timestamp class_id score x y w h [instance_id]
// (seconds; class id into the names file; score in [0,1]; box top-left and size in pixels).
#include <map>

#include "mrpt_yesslam/detection/CObjectDetector.h"

namespace mrpt_yesslam
{
/** One line of a detections file, with its line number for messages. */
struct TDetectionRecord
{
	double t = 0;
	TDetection det;
	std::size_t line = 0;
};

/** Parses detections text; throws InputError naming the line for malformed values, negative
 * sizes, scores outside [0,1] or negative class ids. */
std::vector<TDetectionRecord> parseDetectionsText(const std::string& text, const std::string& nameForErrors);

/** Writes detections in the file format above, atomically. */
void writeDetectionsFile(const std::string& path, const std::vector<TDetectionRecord>& records);

/** The "file" backend. */
class CDetectionsFileDetector : public CObjectDetector
{
   public:
	/** Reads [Detector] file and the names file (if given; else class ids are named "class N"). */
	explicit CDetectionsFileDetector(const TOptions& opts);
	std::string description() const override;

   protected:
	/** The detections whose stamp is nearest to `timestamp` within fileMaxDiff (none otherwise).
	 * Throws InputError for a box that lies wholly outside the image. */
	std::vector<TDetection> detectImpl(const cv::Mat& bgr, double timestamp) override;

   private:
	std::map<double, std::vector<TDetectionRecord>> byStamp_;
	std::string path_;
};
}  // namespace mrpt_yesslam
