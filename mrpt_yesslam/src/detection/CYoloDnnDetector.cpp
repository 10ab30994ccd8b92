#include "mrpt_yesslam/detection/CYoloDnnDetector.h"

#include <stdexcept>
#include <opencv2/core/utility.hpp>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <map>
#include <opencv2/core/utils/logger.hpp>
#include <opencv2/imgproc.hpp>

#include "mrpt_yesslam/util/TextParsing.h"
#include "mrpt_yesslam/util/Error.h"

namespace fs = std::filesystem;

namespace mrpt_yesslam
{
std::size_t darknetWeightsBytes(const std::string& cfgPath)
{
	// Sections in order with their keys.
	std::vector<std::pair<std::string, std::map<std::string, std::string>>> sections;
	for (std::string line : splitLines(readTextFile(cfgPath)))
	{
		line.erase(std::remove_if(line.begin(), line.end(), [](unsigned char c) { return std::isspace(c); }),
				   line.end());
		if (line.empty() || line[0] == '#' || line[0] == ';') continue;
		if (line[0] == '[')
			sections.push_back({line.substr(1, line.find(']') - 1), {}});
		else if (const auto eq = line.find('='); eq != std::string::npos && !sections.empty())
			sections.back().second[line.substr(0, eq)] = line.substr(eq + 1);
	}
	auto integer = [](const std::map<std::string, std::string>& kv, const char* key, long dflt)
	{
		const auto it = kv.find(key);
		return it == kv.end() ? dflt : std::strtol(it->second.c_str(), nullptr, 10);
	};
	if (sections.empty() || (sections[0].first != "net" && sections[0].first != "network")) return 0;
	std::vector<long> channels;  // output channels of each layer
	long c = integer(sections[0].second, "channels", 3);
	std::size_t floats = 0;
	for (std::size_t i = 1; i < sections.size(); i++)
	{
		const auto& [type, kv] = sections[i];
		if (type == "convolutional")
		{
			const long n = integer(kv, "filters", 1), size = integer(kv, "size", 1),
					   groups = std::max(1L, integer(kv, "groups", 1));
			floats += static_cast<std::size_t>(n * (integer(kv, "batch_normalize", 0) ? 4 : 1) +
											   n * (c / groups) * size * size);
			c = n;
		}
		else if (type == "route")
		{
			long sum = 0;
			std::string list = kv.count("layers") ? kv.at("layers") : "";
			for (std::size_t a = 0; a <= list.size();)
			{
				const auto b = std::min(list.find(',', a), list.size());
				long idx = std::strtol(list.substr(a, b - a).c_str(), nullptr, 10);
				if (idx < 0) idx += static_cast<long>(channels.size());
				if (idx < 0 || idx >= static_cast<long>(channels.size())) return 0;
				sum += channels[static_cast<std::size_t>(idx)];
				a = b + 1;
			}
			c = sum / std::max(1L, integer(kv, "groups", 1));
		}
		else if (type != "shortcut" && type != "upsample" && type != "maxpool" && type != "dropout" && type != "yolo" &&
				 type != "avgpool" && type != "region")
			return 0;
		channels.push_back(c);
	}
	return 20 + 4 * floats;  // header: major, minor, revision (int32) and images seen (int64)
}

namespace
{
std::string shapeText(const cv::Mat& m)
{
	std::string s = "[";
	for (int i = 0; i < m.dims; i++) s += (i ? "," : "") + std::to_string(m.size[i]);
	return s + "]";
}

std::string extensionOf(const std::string& p)
{
	std::string e = fs::path(p).extension().string();
	std::transform(e.begin(), e.end(), e.begin(), [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
	return e;
}

// The network side written in a darknet cfg's [net] section ("width=320").
int darknetInputSize(const std::string& cfg)
{
	for (const auto& l : splitLines(readTextFile(cfg)))
	{
		std::string t;
		for (char c : l)
			if (c != ' ' && c != '\t') t += c;
		double v;
		if (t.rfind("width=", 0) == 0 && parseFiniteDouble(t.substr(6), v) && v >= 32 && v <= 4096)
			return static_cast<int>(v);
	}
	return 416;
}

// Rows of a stride-8/16/32 grid for a square input of this side.
int gridCells(int size)
{
	int n = 0;
	for (int s : {8, 16, 32}) n += (size / s) * (size / s);
	return n;
}
}  // namespace

std::string CYoloDnnDetector::formatName(Format f)
{
	switch (f)
	{
		case Format::Darknet: return "darknet";
		case Format::YoloV5: return "yolov5";
		case Format::YoloV8: return "yolov8";
		case Format::YoloX: return "yolox";
		case Format::FastestDet: return "fastestdet";
		case Format::NanoDet: return "nanodet";
	}
	return "?";
}

CYoloDnnDetector::CYoloDnnDetector(const TOptions& o) : CObjectDetector(o), modelPath_(o.model)
{
	if (o.model.empty()) throw InputError("", "[Detector] model is not set (a .cfg + .weights or an .onnx file)");
	std::error_code ec;
	if (!fs::is_regular_file(o.model, ec)) throw InputError(o.model, "model file not found");
	if (o.names.empty()) throw InputError(o.model, "[Detector] names is not set (the class names file of this model)");
	// Process-wide in OpenCV. 0: every core but two, at least one, never more than the process already allows (a test's
	// or a caller's own limit stays): the frame thread and the mapping stages run beside inference, and OpenCV's
	// default (a thread per core) took the core the frame thread needed and slowed the run.
	if (o.threads > 0)
		cv::setNumThreads(o.threads);
	else if (const int automatic = std::max(1, cv::getNumberOfCPUs() - 2); automatic < cv::getNumThreads())
		cv::setNumThreads(automatic);
	const std::string ext = extensionOf(o.model);
	try
	{
		if (ext == ".cfg")
		{
			if (o.weights.empty()) throw InputError(o.model, "darknet model needs [Detector] weights (.weights file)");
			if (!fs::is_regular_file(o.weights, ec)) throw InputError(o.weights, "weights file not found");
			if (const std::size_t expected = darknetWeightsBytes(o.model);
				expected && fs::file_size(o.weights, ec) != expected)
				throw InputError(o.weights, "weights do not match " + fs::path(o.model).filename().string() +
												" (that network needs " + std::to_string(expected) +
												" bytes, the file has " + std::to_string(fs::file_size(o.weights, ec)) +
												"): weights of another model?");
			net_ = cv::dnn::readNetFromDarknet(o.model, o.weights);
			format_ = Format::Darknet;
		}
		else if (ext == ".onnx")
			net_ = cv::dnn::readNetFromONNX(o.model);
		else
			throw InputError(o.model, "unknown model type '" + ext + "' (expected .cfg + .weights or .onnx)");
	}
	catch (const cv::Exception& e)
	{
		throw InputError(ext == ".cfg" ? o.model + " + " + o.weights : o.model,
						 "cannot load model (" + exceptionSummary(e.what()) + ")");
	}
	if (net_.empty()) throw InputError(o.model, "cannot load model (empty network)");
	net_.setPreferableBackend(cv::dnn::DNN_BACKEND_OPENCV);
	net_.setPreferableTarget(cv::dnn::DNN_TARGET_CPU);
	outNames_ = net_.getUnconnectedOutLayersNames();

	if (o.format != "auto")
	{
		static const std::map<std::string, Format> byName = {
			{"darknet", Format::Darknet}, {"yolov5", Format::YoloV5}, {"yolov7", Format::YoloV5},
			{"yolov8", Format::YoloV8},   {"yolox", Format::YoloX},   {"fastestdet", Format::FastestDet},
			{"nanodet", Format::NanoDet}};
		const auto it = byName.find(o.format);
		if (it == byName.end())
			throw InputError(
				o.model, "unknown [Detector] format '" + o.format + "' (auto, darknet, yolov5, yolov7, yolov8, yolox)");
		format_ = it->second;
	}

	// Probe the input size with a blank image: fixed-size ONNX exports fail at any other size. The
	// run also tells the output layout and proves the model really runs.
	std::vector<int> sizes;
	if (o.inputSize > 0)
		sizes = {o.inputSize};
	else if (format_ == Format::Darknet)
		sizes = {darknetInputSize(o.model)};
	else
		sizes = {640, 416, 320, 352, 512};
	std::string lastError = "no size tried";
	// A wrong size makes OpenCV log several [ERROR] lines before it throws: silence them while probing.
	const auto logLevel = cv::utils::logging::getLogLevel();
	cv::utils::logging::setLogLevel(cv::utils::logging::LOG_LEVEL_SILENT);
	struct RestoreLog
	{
		cv::utils::logging::LogLevel l;
		~RestoreLog() { cv::utils::logging::setLogLevel(l); }
	} restore{logLevel};
	for (int s : sizes)
	{
		try
		{
			TFit fit;
			const auto outs = forward(makeBlob(cv::Mat(s, s, CV_8UC3, cv::Scalar(114, 114, 114)), s, fit));
			if (!recognise(outs, s))
			{
				std::string shapes;
				for (const auto& m : outs) shapes += (shapes.empty() ? "" : " ") + shapeText(m);
				throw InputError(o.model, "output shape " + shapes +
											  " is not a YOLO layout this reader knows (set [Detector] format; "
											  "YOLOv7 must be exported without NMS)");
			}
			size_ = s;
			break;
		}
		catch (const cv::Exception& e)
		{
			lastError = exceptionSummary(e.what());
		}
	}
	if (size_ == 0)
		throw InputError(
			o.model, "the network does not run at input size(s) tried (" + lastError + "); set [Detector] inputSize");
	setClassNames(readClassNames(o.names, static_cast<std::size_t>(numClasses_)), o.names);
}

std::string CYoloDnnDetector::description() const
{
	return "yolo " + formatName(format_) + " " + std::to_string(size_) + "x" + std::to_string(size_) + " " +
		   fs::path(modelPath_).filename().string() + " (" + std::to_string(numClasses_) + " classes)";
}

bool CYoloDnnDetector::recognise(const std::vector<cv::Mat>& outs, int size)
{
	if (outs.empty()) return false;
	if (format_ == Format::Darknet)
	{
		// Darknet region layers: one 2-D [rows, 5+C] matrix per YOLO head.
		for (const auto& m : outs)
			if (m.dims != 2 || m.cols < 6) return false;
		numClasses_ = outs[0].cols - 5;
		return true;
	}
	const bool auto_ = opts_.format == "auto";
	// NanoDet: per stride 8/16/32 one (N,C) class map and one (N,32) distance map.
	if (outs.size() == 6 && (auto_ || format_ == Format::NanoDet))
	{
		int classes = -1, dists = 0;
		for (const auto& m : outs)
		{
			const int last = m.size[m.dims - 1];
			if (last == 32)
				dists++;
			else if (classes < 0 || classes == last)
				classes = last;
			else
				return false;
		}
		if (dists != 3 || classes < 1) return false;
		format_ = Format::NanoDet;
		numClasses_ = classes;
		return true;
	}
	if (outs.size() != 1) return false;
	const cv::Mat& m = outs[0];
	if (m.dims == 4 && m.size[0] == 1 && m.size[1] >= 6 && (auto_ || format_ == Format::FastestDet))
	{
		format_ = Format::FastestDet;
		numClasses_ = m.size[1] - 5;
		return true;
	}
	if (m.dims != 3 || m.size[0] != 1) return false;
	const int a = m.size[1], b = m.size[2];
	if (auto_)
	{
		if (a > b && b >= 6)
			format_ = (a == gridCells(size)) ? Format::YoloX : Format::YoloV5;
		else if (b > a && a >= 5)
			format_ = Format::YoloV8;
		else
			return false;
	}
	if (format_ == Format::YoloV8)
	{
		if (a < 5) return false;
		numClasses_ = a - 4;
	}
	else
	{
		if (b < 6) return false;
		if (format_ == Format::YoloX && a != gridCells(size)) return false;
		numClasses_ = b - 5;
	}
	return true;
}

cv::Mat CYoloDnnDetector::makeBlob(const cv::Mat& bgr, int size, TFit& fit) const
{
	if (format_ == Format::FastestDet)
	{
		// FastestDet's reference pre-processing: area resize, BGR, /255.
		fit.sx = static_cast<double>(size) / bgr.cols;
		fit.sy = static_cast<double>(size) / bgr.rows;
		cv::Mat resized;
		cv::resize(bgr, resized, cv::Size(size, size), 0, 0, cv::INTER_AREA);
		return cv::dnn::blobFromImage(resized, 1.0 / 255.0, cv::Size(), cv::Scalar(), false, false);
	}
	if (format_ == Format::Darknet)
	{
		// Darknet models are trained on plainly resized images.
		fit.sx = static_cast<double>(size) / bgr.cols;
		fit.sy = static_cast<double>(size) / bgr.rows;
		fit.dx = fit.dy = 0;
		return cv::dnn::blobFromImage(bgr, 1.0 / 255.0, cv::Size(size, size), cv::Scalar(), true, false);
	}
	// Letterbox: keep the aspect ratio, pad with grey 114 (centred for YOLOv5/v8, top-left for YOLOX,
	// as their reference pre-processing does).
	const double r = std::min(static_cast<double>(size) / bgr.cols, static_cast<double>(size) / bgr.rows);
	const int w = static_cast<int>(std::round(bgr.cols * r)), h = static_cast<int>(std::round(bgr.rows * r));
	fit.sx = fit.sy = r;
	fit.dx = format_ == Format::YoloX ? 0 : (size - w) / 2;
	fit.dy = format_ == Format::YoloX ? 0 : (size - h) / 2;
	cv::Mat canvas(size, size, CV_8UC3, cv::Scalar(114, 114, 114)), resized;
	cv::resize(bgr, resized, cv::Size(w, h), 0, 0, cv::INTER_LINEAR);
	resized.copyTo(canvas(cv::Rect(static_cast<int>(fit.dx), static_cast<int>(fit.dy), w, h)));
	if (format_ == Format::YoloX) return cv::dnn::blobFromImage(canvas, 1.0, cv::Size(), cv::Scalar(), false, false);
	if (format_ == Format::NanoDet)
	{
		// NanoDet: BGR, (x - mean) / std per channel.
		cv::Mat f;
		canvas.convertTo(f, CV_32FC3);
		f -= cv::Scalar(103.53, 116.28, 123.675);
		cv::divide(f, cv::Scalar(57.375, 57.12, 58.395), f);
		return cv::dnn::blobFromImage(f, 1.0, cv::Size(), cv::Scalar(), false, false);
	}
	return cv::dnn::blobFromImage(canvas, 1.0 / 255.0, cv::Size(), cv::Scalar(), true, false);
}

std::vector<cv::Mat> CYoloDnnDetector::forward(const cv::Mat& blob)
{
	if (released()) throw std::logic_error("the detector's model was released (releaseModel): no inference after that");
	net_.setInput(blob);
	std::vector<cv::Mat> outs;
	net_.forward(outs, outNames_);
	return outs;
}

std::vector<cv::Mat> CYoloDnnDetector::rawOutputs(const cv::Mat& bgr, TFit& fit)
{
	return forward(makeBlob(bgr, size_, fit));
}

std::vector<TDetection> CYoloDnnDetector::detectImpl(const cv::Mat& bgr, double)
{
	TFit fit;
	const auto outs = forward(makeBlob(bgr, size_, fit));
	return decode(outs, format_, size_, numClasses_, fit, static_cast<float>(opts_.confThreshold),
				  static_cast<float>(opts_.nmsThreshold));
}

std::vector<TDetection> CYoloDnnDetector::decode(const std::vector<cv::Mat>& outs, Format format, int inputSize,
												 int numClasses, const TFit& fit, float thr, float nms)
{
	std::vector<TDetection> cands;
	// Adds a candidate from a box centre/size in network-input pixels.
	auto add = [&](float cx, float cy, float w, float h, const float* cls, float obj)
	{
		int best = 0;
		for (int c = 1; c < numClasses; c++)
			if (cls[c] > cls[best]) best = c;
		const float score = obj * cls[best];
		if (!(score >= thr)) return;
		TDetection d;
		d.classId = best;
		d.score = score;
		d.box = cv::Rect2f(static_cast<float>((cx - w / 2 - fit.dx) / fit.sx),
						   static_cast<float>((cy - h / 2 - fit.dy) / fit.sy), static_cast<float>(w / fit.sx),
						   static_cast<float>(h / fit.sy));
		cands.push_back(d);
	};
	const float S = static_cast<float>(inputSize);
	switch (format)
	{
		case Format::Darknet:
			// Region layer rows: normalised cx cy w h, objectness, class scores already times objectness.
			for (const auto& m : outs)
				for (int r = 0; r < m.rows; r++)
				{
					const float* p = m.ptr<float>(r);
					if (p[4] < thr) continue;
					add(p[0] * S, p[1] * S, p[2] * S, p[3] * S, p + 5, 1.0f);
				}
			break;
		case Format::YoloV5:
		{
			const cv::Mat m = outs[0].reshape(1, outs[0].size[1]);
			for (int r = 0; r < m.rows; r++)
			{
				const float* p = m.ptr<float>(r);
				if (p[4] < thr) continue;
				add(p[0], p[1], p[2], p[3], p + 5, p[4]);
			}
			break;
		}
		case Format::YoloV8:
		{
			const cv::Mat m = outs[0].reshape(1, outs[0].size[1]).t();  // [N, 4+C]
			for (int r = 0; r < m.rows; r++)
			{
				const float* p = m.ptr<float>(r);
				add(p[0], p[1], p[2], p[3], p + 4, 1.0f);
			}
			break;
		}
		case Format::YoloX:
		{
			// Raw head outputs: xy = (out + grid) * stride, wh = exp(out) * stride, rows by stride 8, 16, 32.
			const cv::Mat m = outs[0].reshape(1, outs[0].size[1]);
			int r = 0;
			for (int s : {8, 16, 32})
			{
				const int g = inputSize / s;
				for (int gy = 0; gy < g; gy++)
					for (int gx = 0; gx < g; gx++, r++)
					{
						const float* p = m.ptr<float>(r);
						if (p[4] < thr) continue;
						add((p[0] + gx) * s, (p[1] + gy) * s, std::exp(p[2]) * s, std::exp(p[3]) * s, p + 5, p[4]);
					}
			}
			break;
		}
		case Format::FastestDet:
		{
			// One cell per row/col: [obj, dx, dy, w, h, classes]; boxes normalised to the image.
			const cv::Mat& m = outs[0];
			const int C = m.size[1], H = m.size[2], W = m.size[3];
			const float* base = m.ptr<float>();
			const std::size_t plane = static_cast<std::size_t>(H) * W;
			std::vector<float> cls(static_cast<std::size_t>(numClasses));
			for (int row = 0; row < H; row++)
				for (int col = 0; col < W; col++)
				{
					const std::size_t at = static_cast<std::size_t>(row) * W + col;
					auto ch = [&](int c) { return base[static_cast<std::size_t>(c) * plane + at]; };
					const float obj = ch(0);
					if (obj <= 0) continue;
					for (int c = 5; c < C; c++)
						cls[static_cast<std::size_t>(c - 5)] = std::pow(std::max(0.f, ch(c)), 0.4f);
					const float cx = (col + std::tanh(ch(1))) / W * S, cy = (row + std::tanh(ch(2))) / H * S;
					const float w = 1.f / (1.f + std::exp(-ch(3))) * S, h = 1.f / (1.f + std::exp(-ch(4))) * S;
					add(cx, cy, w, h, cls.data(), std::pow(obj, 0.6f));
				}
			break;
		}
		case Format::NanoDet:
		{
			// Pair class and distance maps by their row count, one pair per stride.
			for (int s : {8, 16, 32})
			{
				const int g = inputSize / s, n = g * g;
				const cv::Mat *cm = nullptr, *dm = nullptr;
				for (const auto& o : outs)
				{
					const int last = o.size[o.dims - 1];
					if (static_cast<int>(o.total()) / last != n) continue;
					(last == 32 ? dm : cm) = &o;
				}
				if (!cm || !dm) continue;
				const float* cp = cm->ptr<float>();
				const float* dp = dm->ptr<float>();
				for (int i = 0; i < n; i++)
				{
					const float* cls = cp + static_cast<std::size_t>(i) * numClasses;
					const float best = *std::max_element(cls, cls + numClasses);
					if (best < thr) continue;
					// GFL: each side a softmax over 8 bins, its expectation times the stride.
					float side[4];
					for (int k = 0; k < 4; k++)
					{
						const float* b = dp + static_cast<std::size_t>(i) * 32 + k * 8;
						const float mx = *std::max_element(b, b + 8);
						float den = 0, num = 0;
						for (int j = 0; j < 8; j++)
						{
							const float e = std::exp(b[j] - mx);
							den += e;
							num += e * j;
						}
						side[k] = num / den * s;
					}
					const float ax = (i % g) * s + (s - 1) / 2.0f, ay = (i / g) * s + (s - 1) / 2.0f;
					const float x1 = ax - side[0], y1 = ay - side[1], x2 = ax + side[2], y2 = ay + side[3];
					add((x1 + x2) / 2, (y1 + y2) / 2, x2 - x1, y2 - y1, cls, 1.0f);
				}
			}
			break;
		}
	}
	// Class-wise non-maximum suppression.
	std::map<int, std::vector<int>> byClass;
	for (int i = 0; i < static_cast<int>(cands.size()); i++)
		byClass[cands[static_cast<std::size_t>(i)].classId].push_back(i);
	std::vector<TDetection> out;
	for (const auto& [cls, idx] : byClass)
	{
		std::vector<cv::Rect2d> boxes;
		std::vector<float> scores;
		for (int i : idx)
		{
			boxes.emplace_back(cands[static_cast<std::size_t>(i)].box);
			scores.push_back(cands[static_cast<std::size_t>(i)].score);
		}
		std::vector<int> keep;
		cv::dnn::NMSBoxes(boxes, scores, thr, nms, keep);
		for (int k : keep) out.push_back(cands[static_cast<std::size_t>(idx[static_cast<std::size_t>(k)])]);
	}
	std::sort(out.begin(), out.end(), [](const TDetection& a, const TDetection& b) { return a.score > b.score; });
	return out;
}
}  // namespace mrpt_yesslam
