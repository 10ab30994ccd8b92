#include "mrpt_yesslam/detection/CDetectionsFileDetector.h"

#include <cmath>
#include <cstdio>
#include <filesystem>

#include "mrpt_yesslam/util/TextParsing.h"
#include "mrpt_yesslam/util/AtomicFile.h"
#include "mrpt_yesslam/util/Error.h"
#include "mrpt_yesslam/util/ShareDir.h"

namespace mrpt_yesslam
{
std::vector<TDetectionRecord> parseDetectionsText(const std::string& text, const std::string& name)
{
	std::vector<TDetectionRecord> out;
	const auto lines = splitLines(text);
	for (std::size_t i = 0; i < lines.size(); i++)
	{
		if (isCommentOrBlank(lines[i])) continue;
		const std::string where = "line " + std::to_string(i + 1) + ": ";
		const auto f = splitFields(lines[i]);
		if (f.size() != 7 && f.size() != 8)
			throw InputError(name, where + "expected 'timestamp class_id score x y w h [instance_id]', found " +
									   std::to_string(f.size()) + " fields");
		double v[8] = {0, 0, 0, 0, 0, 0, 0, -1};
		for (std::size_t k = 0; k < f.size(); k++)
			if (!parseFiniteDouble(f[k], v[k]))
				throw InputError(name,
								 where + "field " + std::to_string(k + 1) + " '" + f[k] + "' is not a finite number");
		if (v[1] < 0 || v[1] != std::floor(v[1]) || v[1] > 1e6)
			throw InputError(name, where + "class_id must be a non-negative integer");
		if (v[2] < 0 || v[2] > 1) throw InputError(name, where + "score must be in [0,1]");
		if (v[5] <= 0 || v[6] <= 0) throw InputError(name, where + "box width and height must be positive");
		for (int k = 3; k < 7; k++)
			if (std::abs(v[k]) > 1e6) throw InputError(name, where + "box coordinates must be within +-1e6 pixels");
		if (f.size() == 8 && (v[7] != std::floor(v[7]) || v[7] < -1 || v[7] > 2147483647.0))
			throw InputError(name, where + "instance_id must be an integer from -1 to 2^31-1");
		TDetectionRecord r;
		r.t = v[0];
		r.line = i + 1;
		r.det.classId = static_cast<int>(v[1]);
		r.det.score = static_cast<float>(v[2]);
		r.det.box = cv::Rect2f(static_cast<float>(v[3]), static_cast<float>(v[4]), static_cast<float>(v[5]),
							   static_cast<float>(v[6]));
		r.det.instanceId = static_cast<int>(v[7]);
		out.push_back(r);
	}
	return out;
}

void writeDetectionsFile(const std::string& path, const std::vector<TDetectionRecord>& records)
{
	std::string s = "# timestamp class_id score x y w h instance_id\n";
	char buf[256];
	for (const auto& r : records)
	{
		std::snprintf(buf, sizeof(buf), "%.6f %d %.4f %.2f %.2f %.2f %.2f %d\n", r.t, r.det.classId, r.det.score,
					  r.det.box.x, r.det.box.y, r.det.box.width, r.det.box.height, r.det.instanceId);
		s += buf;
	}
	writeFileAtomically(path, s);
}

CDetectionsFileDetector::CDetectionsFileDetector(const TOptions& o) : CObjectDetector(o), path_(o.file)
{
	if (o.file.empty()) throw InputError("", "[Detector] file is not set (the detections.txt to read)");
	for (auto& r : parseDetectionsText(readTextFile(o.file), o.file)) byStamp_[r.t].push_back(r);
	int maxClass = 0;
	for (const auto& kv : byStamp_)
		for (const auto& r : kv.second) maxClass = std::max(maxClass, r.det.classId);
	std::vector<std::string> names;
	if (!o.names.empty())
	{
		names = readClassNames(o.names);
		if (static_cast<std::size_t>(maxClass) >= names.size())
			throw InputError(o.file, "class id " + std::to_string(maxClass) + " but " + o.names + " has only " +
										 std::to_string(names.size()) + " names");
	}
	else
	{
		// Without a names file the ids are taken as COCO's (0 is "person"): named from the shipped
		// coco.names when it is there (the dense map's labels and legend), else by number.
		const std::string share = shareDir();
		const std::string coco = share.empty() ? std::string() : share + "/models/yolo-fastest-1.1/coco.names";
		std::error_code ec;
		if (!coco.empty() && std::filesystem::exists(coco, ec)) names = readClassNames(coco);
		if (names.empty() || static_cast<std::size_t>(maxClass) >= names.size())
		{
			names = {"person"};
			for (int c = 1; c <= maxClass; c++) names.push_back("class " + std::to_string(c));
		}
	}
	setClassNames(names, o.names.empty() ? o.file : o.names);
}

std::string CDetectionsFileDetector::description() const
{
	return "file " + path_ + " (" + std::to_string(byStamp_.size()) + " frames with detections)";
}

std::vector<TDetection> CDetectionsFileDetector::detectImpl(const cv::Mat& bgr, double t)
{
	if (byStamp_.empty()) return {};
	auto it = byStamp_.lower_bound(t);
	auto best = byStamp_.end();
	if (it != byStamp_.end()) best = it;
	if (it != byStamp_.begin())
	{
		auto prev = std::prev(it);
		if (best == byStamp_.end() || std::abs(prev->first - t) < std::abs(best->first - t)) best = prev;
	}
	if (best == byStamp_.end() || std::abs(best->first - t) > opts_.fileMaxDiff) return {};
	std::vector<TDetection> out;
	const cv::Rect2f image(0, 0, static_cast<float>(bgr.cols), static_cast<float>(bgr.rows));
	for (const auto& r : best->second)
	{
		if ((r.det.box & image).area() <= 0)
			throw InputError(path_, "line " + std::to_string(r.line) + ": box lies outside the " +
										std::to_string(bgr.cols) + "x" + std::to_string(bgr.rows) + " image");
		out.push_back(r.det);
	}
	return out;
}
}  // namespace mrpt_yesslam
