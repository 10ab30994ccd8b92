// The input of a run: the detector the input implies, the input's file, and the input chain.
#include "SlamJobInput.h"

#include <filesystem>

#include "mrpt_yesslam/io/COpenNI2Source.h"
#include "mrpt_yesslam/io/CPacedSource.h"
#include "mrpt_yesslam/io/CPrefetchingSource.h"
#include "mrpt_yesslam/util/Error.h"

namespace fs = std::filesystem;

namespace mrpt_yesslam
{
void resolveDetector(CObjectDetector::TOptions& det, const std::string& input)
{
	const fs::path in(input);
	// A camera has no folder: nothing lies beside it.
	const fs::path beside = input.empty()          ? fs::path()
							: fs::is_directory(in) ? in / "detections.txt"
												   : in.parent_path() / "detections.txt";
	if (det.backend == "auto")
	{
		if (!det.file.empty() || (!beside.empty() && fs::exists(beside)))
			det.backend = "file";
		else if (useShippedModel(det))  // the configured model, else the shipped Yolo-Fastest
			det.backend = "yolo";
		else
			det.backend = "hog";
	}
	if (det.backend == "file" && det.file.empty())
	{
		if (beside.empty() || !fs::exists(beside))
			throw InputError(beside.empty() ? std::string("openni2") : beside.string(),
							 "not found: the file detector needs [Detector] file or a detections.txt beside the input");
		det.file = beside.string();
	}
	if (det.backend == "yolo" && !useShippedModel(det))
		throw InputError("",
						 "the yolo detector needs [Detector] model (and names): the shipped share/mrpt_yesslam/models "
						 "was not found (set YESSLAM_SHARE_DIR); or use --detector file, hog or none");
}

std::string inputFilePath(const std::string& input)
{
	if (isOpenNI2Input(input)) return input.size() > 8 ? input.substr(8) : std::string();
	return input;
}

namespace job_detail
{
TInputChain openInput(const TSlamJobOptions& o, const TYesSlamOptions& opts,
					  const std::function<void(const mrpt::obs::CObservation3DRangeScan::Ptr&)>& record)
{
	TInputChain c;
	const auto& L = o.live;
	if (L.width <= 0 || L.height <= 0 || L.fps <= 0)
		throw InputError("", "the camera's width, height and fps must be > 0");
	if (!(L.speed > 0)) throw InputError("", "the playback speed must be > 0, got " + std::to_string(L.speed));
	if (isOpenNI2Input(o.input))
	{
		COpenNI2Source::TOptions co;
		co.uri = inputFilePath(o.input);
		co.width = L.width;
		co.height = L.height;
		co.fps = L.fps;
		co.camera = opts.input.camera;
		co.timeoutSeconds = L.timeoutSeconds;
		// A file in sequential mode plays one frame per request: nothing dropped, deterministic.
		const bool fileInOrder = !co.uri.empty() && !opts.system.parallel && !L.realtime;
		co.playbackSpeed = fileInOrder ? -1.0 : L.speed;
		auto cam = std::make_unique<COpenNI2Source>(co);
		c.device = cam->description();
		const COpenNI2Source* raw = cam.get();
		c.disconnected = [raw] { return raw->disconnected(); };
		auto live = std::make_unique<CLiveSource>(std::move(cam), L.slots, !fileInOrder, record);
		c.live = live.get();
		c.source = std::move(live);
		return c;
	}
	std::unique_ptr<CInputSource> src = openInputSource(o.input, opts.input);
	if (L.realtime)
	{
		auto live = std::make_unique<CLiveSource>(std::make_unique<CPacedSource>(std::move(src), L.speed), L.slots,
												  true, record);
		c.live = live.get();
		c.source = std::move(live);
		return c;
	}
	if (opts.input.prefetch > 0)
		src = std::make_unique<CPrefetchingSource>(std::move(src), static_cast<std::size_t>(opts.input.prefetch));
	c.source = std::move(src);
	return c;
}
}  // namespace job_detail
}  // namespace mrpt_yesslam
