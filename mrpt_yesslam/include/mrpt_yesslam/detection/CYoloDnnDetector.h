#pragma once
// YOLO-family detectors through OpenCV DNN on the CPU: Darknet cfg+weights (Yolo-Fastest, YOLOv3/4),
// and ONNX exports of YOLOv5/YOLOv7 ([1,N,5+C], objectness x class score), YOLOv8 ([1,4+C,N], no
// objectness) and YOLOX ([1,N,5+C], raw grid offsets); also FastestDet and NanoDet-m. The layout is recognised from the
// output tensor shape (or forced with [Detector] format), the input size from the model.
#include <opencv2/dnn.hpp>

#include "mrpt_yesslam/detection/CObjectDetector.h"

namespace mrpt_yesslam
{
/** The size in bytes a darknet .weights file must have for the network of `cfgPath` (header and
 * every layer's parameters, as darknet's load_weights reads them), or 0 when the cfg holds a layer
 * type this count does not know. OpenCV reads as many values as the cfg asks for and ignores the
 * rest, so weights of another model load without error and detect nothing. */
std::size_t darknetWeightsBytes(const std::string& cfgPath);

/** Detector running a YOLO network with cv::dnn. */
class CYoloDnnDetector : public CObjectDetector
{
   public:
	/** Output layouts this class decodes. */
	enum class Format
	{
		Darknet,
		YoloV5,  //!< also YOLOv7 exported without NMS
		YoloV8,
		YoloX,
		FastestDet,  //!< [1,5+C,H,W] grid, score = obj^0.6 * cls^0.4
		NanoDet      //!< per stride a (N,C) class map and a (N,32) GFL distance map
	};

	/** Loads the model and names, probes the input size and output layout; throws InputError naming
	 * the file for a missing or unloadable model or a names file with the wrong count. */
	explicit CYoloDnnDetector(const TOptions& opts);
	std::string description() const override;
	Format format() const { return format_; }
	int inputSize() const { return size_; }
	/** Name of a format, as in the config ("darknet", "yolov5", ...). */
	static std::string formatName(Format f);

	/** How the image was fitted into the network input: input = image * scale + offset. */
	struct TFit
	{
		double sx = 1, sy = 1, dx = 0, dy = 0;
	};
	/** The network's raw outputs for an image, and how the image was fitted into its input. */
	std::vector<cv::Mat> rawOutputs(const cv::Mat& bgr, TFit& fit);
	/** Decodes raw outputs of a network of the given layout (input side `inputSize`, `numClasses`
	 * classes) into boxes in image pixels, with the confidence threshold and class-wise NMS. Static
	 * so that every layout can be checked on any tensor of its shape. */
	static std::vector<TDetection> decode(const std::vector<cv::Mat>& outs, Format format, int inputSize,
										  int numClasses, const TFit& fit, float confThreshold, float nmsThreshold);

   protected:
	std::vector<TDetection> detectImpl(const cv::Mat& bgr, double timestamp) override;
	void releaseModelImpl() override { net_ = cv::dnn::Net(); }

   private:
	cv::Mat makeBlob(const cv::Mat& bgr, int size, TFit& fit) const;
	std::vector<cv::Mat> forward(const cv::Mat& blob);
	/** Decides the format and class count from output shapes; false if unknown. */
	bool recognise(const std::vector<cv::Mat>& outs, int size);

	cv::dnn::Net net_;
	std::vector<std::string> outNames_;
	Format format_ = Format::YoloV5;
	int size_ = 0;
	int numClasses_ = 0;
	std::string modelPath_;
};
}  // namespace mrpt_yesslam
