#include "mrpt_yesslam/detection/CObjectDetector.h"

#include <filesystem>

#include "mrpt_yesslam/util/ShareDir.h"

#include <mrpt/config/CConfigFileBase.h>

#include <limits>

#include <algorithm>

#include "mrpt_yesslam/detection/CDetectionsFileDetector.h"
#include "mrpt_yesslam/detection/CHogPeopleDetector.h"
#include "mrpt_yesslam/detection/CYoloDnnDetector.h"
#include "mrpt_yesslam/util/TextParsing.h"
#include "mrpt_yesslam/util/Error.h"

namespace mrpt_yesslam
{
const std::vector<std::string>& yoloOutputFormats()
{
	static const std::vector<std::string> f{"auto",   "darknet", "yolov5",     "yolov7",
											"yolov8", "yolox",   "fastestdet", "nanodet"};
	return f;
}

COptionTable CObjectDetector::TOptions::table()
{
	constexpr double kBig = std::numeric_limits<double>::max();
	COptionTable t("Detector");
	t.text("backend", backend, "detector", {"yolo", "file", "hog", "none", "auto"});
	t.text("model", model, "yolo: .cfg (darknet) or .onnx");
	t.text("weights", weights, "yolo darknet: .weights");
	t.text("names", names, "class names file, one per line (COCO order for COCO models)");
	t.text("format", format, "yolo output layout", yoloOutputFormats());
	t.integer("inputSize", inputSize, 0, 4096,
			  "network input side in pixels; 0 = from the model (darknet cfg) or found by probing");
	t.real("confThreshold", confThreshold, 0, 1, "boxes below this confidence are dropped (the paper: 0.6)");
	t.real("nmsThreshold", nmsThreshold, 0, 1, "class-wise non-maximum suppression IoU");
	t.text("dynamicClasses", dynamicClasses, "comma-separated class names treated as dynamic");
	t.text("file", file, "file backend: detections.txt (empty = the one beside the input)");
	t.real("fileMaxDiff", fileMaxDiff, 0, kBig, "file backend: largest frame/detection stamp difference, s");
	t.integer("threads", threads, 0, 256,
			  "OpenCV threads for inference (process-wide); 0 = every core but two (the frame thread and the mapping "
			  "stages), at least one");
	return t;
}

std::string CObjectDetector::className(int id) const
{
	if (id >= 0 && static_cast<std::size_t>(id) < names_.size()) return names_[static_cast<std::size_t>(id)];
	return "class " + std::to_string(id);
}

void CObjectDetector::setClassNames(std::vector<std::string> names, const std::string& source)
{
	names_ = std::move(names);
	dynamicIds_.clear();
	for (const auto& want : splitFields(opts_.dynamicClasses))
	{
		const auto it = std::find(names_.begin(), names_.end(), want);
		if (it == names_.end())
			throw InputError(source, "dynamic class '" + want + "' is not among the " + std::to_string(names_.size()) +
										 " class names");
		dynamicIds_.insert(static_cast<int>(it - names_.begin()));
	}
}

void CObjectDetector::releaseModel()
{
	released_ = true;
	releaseModelImpl();
}

std::vector<TDetection> CObjectDetector::detect(const cv::Mat& bgr, double timestamp)
{
	if (released_) throw std::logic_error("the detector's model was released (releaseModel): no detection after that");
	if (bgr.empty()) return {};
	std::vector<TDetection> out;
	const cv::Rect2f image(0, 0, static_cast<float>(bgr.cols), static_cast<float>(bgr.rows));
	for (auto d : detectImpl(bgr, timestamp))
	{
		if (!(d.score >= opts_.confThreshold)) continue;
		d.box &= image;
		if (d.box.width < 1 || d.box.height < 1) continue;
		d.dynamic = isDynamicClass(d.classId);
		out.push_back(d);
	}
	return out;
}

std::vector<std::string> readClassNames(const std::string& path, std::size_t expected)
{
	std::vector<std::string> names;
	for (auto l : splitLines(readTextFile(path)))
	{
		while (!l.empty() && (l.back() == ' ' || l.back() == '\t')) l.pop_back();
		const auto b = l.find_first_not_of(" \t");
		if (b == std::string::npos) continue;
		names.push_back(l.substr(b));
	}
	if (names.empty()) throw InputError(path, "class names file is empty");
	if (expected > 0 && names.size() != expected)
		throw InputError(path, "has " + std::to_string(names.size()) + " class names but the model outputs " +
								   std::to_string(expected) + " classes");
	return names;
}

namespace
{
// The "none" backend: no detections, so no dynamic filtering (the baseline of the comparisons).
class CNoDetector : public CObjectDetector
{
   public:
	explicit CNoDetector(const TOptions& o) : CObjectDetector(o) { setClassNames({"person"}, "none"); }
	std::string description() const override { return "none"; }

   protected:
	std::vector<TDetection> detectImpl(const cv::Mat&, double) override { return {}; }
};
}  // namespace

bool useShippedModel(CObjectDetector::TOptions& o)
{
	if (!o.model.empty()) return true;
	const std::string share = shareDir();
	if (share.empty()) return false;
	const std::string dir = share + "/models/yolo-fastest-1.1/";
	namespace fs = std::filesystem;
	std::error_code ec;
	if (!fs::exists(dir + "yolo-fastest-1.1.weights", ec)) return false;
	o.model = dir + "yolo-fastest-1.1.cfg";
	o.weights = dir + "yolo-fastest-1.1.weights";
	if (o.names.empty()) o.names = dir + "coco.names";
	if (o.format == "auto") o.format = "darknet";
	return true;
}

std::unique_ptr<CObjectDetector> createObjectDetector(const CObjectDetector::TOptions& opts)
{
	CObjectDetector::TOptions o = opts;
	if (o.backend == "yolo") useShippedModel(o);
	if (!(o.confThreshold >= 0 && o.confThreshold <= 1))
		throw InputError("", "[Detector] confThreshold must be in [0,1]");
	if (!(o.nmsThreshold > 0 && o.nmsThreshold <= 1)) throw InputError("", "[Detector] nmsThreshold must be in (0,1]");
	if (o.backend == "yolo") return std::make_unique<CYoloDnnDetector>(o);
	if (o.backend == "file") return std::make_unique<CDetectionsFileDetector>(o);
	if (o.backend == "hog") return std::make_unique<CHogPeopleDetector>(o);
	if (o.backend == "none") return std::make_unique<CNoDetector>(o);
	if (o.backend == "auto")
	{
		// Without an input to look beside (resolveDetector does that): the configured file, else the
		// configured or shipped model, else HOG, as resolveDetector decides.
		CObjectDetector::TOptions r = o;
		r.backend = !o.file.empty() ? "file" : useShippedModel(r) ? "yolo" : "hog";
		return createObjectDetector(r);
	}
	throw InputError("", "unknown detector backend '" + o.backend + "' (auto, yolo, file, hog or none)");
}
}  // namespace mrpt_yesslam
