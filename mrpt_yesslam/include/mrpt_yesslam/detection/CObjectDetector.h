#pragma once
// The detector interface (paper section 2.1): one call per frame gives the objects in it, with the
// dynamic ones flagged. Backends: YOLO-family networks through OpenCV DNN, a detections file
// computed offline, OpenCV's HOG people detector, or none. As in MRPT's CObjectDetection, the
// public call does the common work (threshold, dynamic flags) around a protected implementation.
#include <mrpt/config/CLoadableOptions.h>

#include <memory>
#include <opencv2/core.hpp>
#include <set>
#include <string>
#include <vector>

#include "mrpt_yesslam/types.h"
#include "mrpt_yesslam/util/ConfigFile.h"
#include "mrpt_yesslam/util/OptionTable.h"

namespace mrpt_yesslam
{
/** Base class of all detector backends. */
class CObjectDetector
{
   public:
	/** Section [Detector] of the config. */
	struct TOptions : public TTableOptions<TOptions>
	{
		/** auto | yolo | file | hog | none. auto (resolveDetector, when the input is known):
		 * detections.txt beside the input, else yolo (the set model, else the shipped one), else hog. */
		std::string backend = "auto";
		std::string model;    //!< yolo: .cfg (darknet) or .onnx
		std::string weights;  //!< yolo darknet: .weights
		std::string names;    //!< class names file, one per line (COCO order for COCO models)
		/** yolo output layout: auto (from tensor shapes) | darknet | yolov5 (also v7) | yolov8 | yolox */
		std::string format = "auto";
		int inputSize = 0;  //!< network input side in pixels; 0 = from the model (darknet cfg) or found by probing
		double confThreshold = 0.6;             //!< the paper drops boxes below 0.6
		double nmsThreshold = 0.45;             //!< class-wise NMS IoU
		std::string dynamicClasses = "person";  //!< comma-separated class names treated as dynamic
		std::string file;                       //!< file backend: detections.txt
		double fileMaxDiff = 0.005;             //!< file backend: largest frame/detection stamp difference, s
		int threads = 0;                        //!< OpenCV threads for inference (0 = every core but two, at least one)

		/** Every option once: key, member, range, help (load, dump and keys come from it). */
		COptionTable table();
	};

	virtual ~CObjectDetector() = default;

	/** Detects objects in a BGR image taken at `timestamp` (seconds; used by the file backend).
	 * Drops boxes below the confidence threshold, clips boxes to the image and flags dynamic ones. */
	std::vector<TDetection> detect(const cv::Mat& bgr, double timestamp);

	/** Class names, indexed by TDetection::classId. */
	const std::vector<std::string>& classNames() const { return names_; }
	/** Name of a class id ("class N" when out of range). */
	std::string className(int classId) const;
	/** Whether a class id is in the dynamic set. */
	bool isDynamicClass(int classId) const { return dynamicIds_.count(classId) > 0; }
	/** A short description of the backend and model, for logs. */
	virtual std::string description() const = 0;
	/** Lets go of the model (weights, layer buffers: about 8 MB for the shipped network) once no
	 * more images will come, as before a run's outputs (issue 41 item 5: they are the run's peak of
	 * memory); class names and description stay. detect() afterwards throws std::logic_error.
	 * Call it from the thread that runs detect() or hands it work (CAsyncDetector::releaseModel). */
	void releaseModel();

   protected:
	explicit CObjectDetector(const TOptions& opts) : opts_(opts) {}
	/** The backend's raw detections (scores in [0,1], boxes in image pixels). */
	virtual std::vector<TDetection> detectImpl(const cv::Mat& bgr, double timestamp) = 0;
	/** The backend's part of releaseModel() (nothing for backends without a model in memory). */
	virtual void releaseModelImpl() {}
	/** Sets the class names and resolves the dynamic class set against them (throws for an unknown
	 * dynamic class name). */
	void setClassNames(std::vector<std::string> names, const std::string& sourceForErrors);

	/** releaseModel() was called (backends check it where they run the model outside detect()). */
	bool released() const { return released_; }

	TOptions opts_;

   private:
	std::vector<std::string> names_;
	std::set<int> dynamicIds_;
	bool released_ = false;
};

/** Reads a class names file (one name per line; blank lines ignored); with expectedCount > 0 the
 * count must match (a names file for another model is a common mistake). Throws InputError. */
std::vector<std::string> readClassNames(const std::string& path, std::size_t expectedCount = 0);

/** The `[Detector] format` values (auto first): one list for the config table and the tools' help. */
const std::vector<std::string>& yoloOutputFormats();

/** Fills an empty `model` (and `weights`, `names`) with the shipped Yolo-Fastest-1.1 COCO
 * (share/mrpt_yesslam/models); false when no model is set and none is shipped. */
bool useShippedModel(CObjectDetector::TOptions& o);

/** Creates the backend the options name (yolo without a model: the shipped one); throws
 * InputError for unknown backends or bad files. */
std::unique_ptr<CObjectDetector> createObjectDetector(const CObjectDetector::TOptions& opts);
}  // namespace mrpt_yesslam
