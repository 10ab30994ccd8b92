#include "mrpt_yesslam/jobs/DetectionJob.h"

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <opencv2/core/utility.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "mrpt_yesslam/detection/CDetectionsFileDetector.h"
#include "mrpt_yesslam/eval/TrajectoryEvaluator.h"
#include "mrpt_yesslam/io/RgbdObservation.h"
#include "mrpt_yesslam/util/AtomicFile.h"
#include "mrpt_yesslam/util/Error.h"

namespace fs = std::filesystem;

namespace mrpt_yesslam
{
namespace
{
bool isImageFile(const std::string& p)
{
	std::string e = fs::path(p).extension().string();
	std::transform(e.begin(), e.end(), e.begin(), [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
	return e == ".png" || e == ".jpg" || e == ".jpeg" || e == ".bmp" || e == ".ppm" || e == ".tif" || e == ".tiff";
}

std::string stampName(double t)
{
	char b[64];
	std::snprintf(b, sizeof(b), "%.6f.png", t);
	return b;
}
}  // namespace

cv::Mat drawDetectionOverlay(const cv::Mat& bgr, const std::vector<TDetection>& dets, const CObjectDetector& det,
							 const cv::Mat& mask)
{
	cv::Mat out = bgr.clone();
	if (!mask.empty())
	{
		cv::Mat red(out.size(), out.type(), cv::Scalar(0, 0, 255));
		cv::Mat blended;
		cv::addWeighted(out, 0.5, red, 0.5, 0, blended);
		blended.copyTo(out, mask);
	}
	for (const auto& d : dets)
	{
		const cv::Scalar col = d.dynamic ? cv::Scalar(0, 0, 255) : cv::Scalar(0, 200, 0);
		cv::rectangle(out, d.box, col, 2);
		char label[128];
		std::snprintf(label, sizeof(label), "%s %.2f", det.className(d.classId).c_str(), d.score);
		int base = 0;
		const cv::Size ts = cv::getTextSize(label, cv::FONT_HERSHEY_SIMPLEX, 0.5, 1, &base);
		const cv::Point org(static_cast<int>(d.box.x), std::max(ts.height + 4, static_cast<int>(d.box.y)));
		cv::rectangle(out, cv::Rect(org.x, org.y - ts.height - 4, ts.width + 4, ts.height + 6), col, cv::FILLED);
		cv::putText(out, label, {org.x + 2, org.y - 2}, cv::FONT_HERSHEY_SIMPLEX, 0.5, cv::Scalar(255, 255, 255), 1,
					cv::LINE_AA);
	}
	return out;
}

TDetectJobSummary runDetectionJob(const TDetectJobOptions& o,
								  const std::function<void(std::size_t, std::size_t)>& progress,
								  const std::function<bool()>& cancel)
{
	std::error_code ec;
	if (o.input.empty()) throw InputError("", "no input given");
	if (!fs::exists(o.input, ec)) throw InputError(o.input, "not found");
	if (o.outDir.empty()) throw InputError("", "no output folder given");
	// Models and options first: a run that cannot start leaves no output folder behind.
	// Nothing runs beside detection here: every core (the detector's own default leaves two to SLAM).
	CObjectDetector::TOptions detectorOptions = o.detector;
	if (detectorOptions.threads == 0) detectorOptions.threads = cv::getNumberOfCPUs();
	auto detector = createObjectDetector(detectorOptions);
	CDynamicObjectMasker masker(o.masker);
	fs::create_directories(o.outDir, ec);
	if (ec || !fs::is_directory(o.outDir)) throw InputError(o.outDir, "cannot create output folder");

	TDetectJobSummary sum;
	std::vector<TDetectionRecord> records;
	std::vector<double> tDet, tMask;
	auto handle = [&](const cv::Mat& bgr, const cv::Mat& depth, double stamp)
	{
		const auto t0 = std::chrono::steady_clock::now();
		const auto dets = detector->detect(bgr, stamp);
		const auto t1 = std::chrono::steady_clock::now();
		tDet.push_back(std::chrono::duration<double, std::milli>(t1 - t0).count());
		cv::Mat mask;
		if (!depth.empty())
		{
			const auto t2 = std::chrono::steady_clock::now();
			mask = masker.compute(depth, dets).mask;
			tMask.push_back(std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t2).count());
			fs::create_directories(fs::path(o.outDir) / "masks");
			writePngAtomically((fs::path(o.outDir) / "masks" / stampName(stamp)).string(), mask);
			sum.masks++;
		}
		if (o.overlay)
		{
			fs::create_directories(fs::path(o.outDir) / "overlays");
			writePngAtomically((fs::path(o.outDir) / "overlays" / stampName(stamp)).string(),
							   drawDetectionOverlay(bgr, dets, *detector, mask));
		}
		for (const auto& d : dets)
		{
			records.push_back({stamp, d, 0});
			sum.detections++;
			sum.dynamicDetections += d.dynamic;
		}
		sum.frames++;
	};

	if (fs::is_regular_file(o.input) && isImageFile(o.input))
	{
		const cv::Mat img = cv::imread(o.input, cv::IMREAD_COLOR);
		if (img.empty()) throw InputError(o.input, "cannot decode image");
		handle(img, cv::Mat(), 0.0);
		if (progress) progress(1, 1);
	}
	else
	{
		auto src = openInputSource(o.input, o.source);
		const std::size_t total =
			o.maxFrames ? std::min(o.maxFrames, src->sizeHint() ? src->sizeHint() : o.maxFrames) : src->sizeHint();
		sum.detectionsFile = (fs::path(o.outDir) / "detections.txt").string();
		try
		{
			while (!o.maxFrames || sum.frames < o.maxFrames)
			{
				if (cancel && cancel())
				{
					sum.interrupted = true;
					break;
				}
				auto obs = src->next();
				if (!obs) break;
				handle(obs->intensityImage.asCvMatRef(), depthInMetres(*obs), observationTime(*obs));
				if (progress) progress(sum.frames, total);
			}
		}
		catch (const std::exception&)
		{
			// A frame that cannot be read: detections.txt still covers exactly the frames whose
			// masks were written, so the two agree.
			writeDetectionsFile(sum.detectionsFile, records);
			throw;
		}
	}
	sum.detectionsFile = (fs::path(o.outDir) / "detections.txt").string();
	writeDetectionsFile(sum.detectionsFile, records);
	sum.detectMsMedian = TErrorStats::of(tDet).median;
	sum.maskMsMedian = TErrorStats::of(tMask).median;
	return sum;
}
}  // namespace mrpt_yesslam
