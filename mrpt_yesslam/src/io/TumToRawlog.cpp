#include "mrpt_yesslam/io/TumToRawlog.h"

#include <mrpt/img/CImage.h>

#include <filesystem>

#include "mrpt_yesslam/io/CRawlogWriter.h"
#include "mrpt_yesslam/io/CTumFolderSource.h"
#include "mrpt_yesslam/io/RgbdObservation.h"
#include "mrpt_yesslam/io/Trajectory.h"
#include "mrpt_yesslam/util/AtomicFile.h"
#include "mrpt_yesslam/util/Error.h"

namespace fs = std::filesystem;

namespace mrpt_yesslam
{
TTumToRawlogSummary convertTumToRawlog(const TTumToRawlogOptions& opts,
									   const std::function<void(std::size_t, std::size_t)>& progress,
									   const std::function<bool()>& cancel)
{
	if (opts.output.empty()) throw InputError("", "no output rawlog given");
	CTumFolderSource src(opts.folder, opts.input);
	TTumToRawlogSummary sum;
	sum.skipped = src.skipped();
	sum.camera = src.camera().name;

	const fs::path out(opts.output);
	std::error_code ec;
	const fs::path outDir = out.parent_path().empty() ? fs::path(".") : out.parent_path();
	// Made when missing, as yesslam --out does (issue 43).
	if (!fs::is_directory(outDir, ec)) fs::create_directories(outDir, ec);
	if (!fs::is_directory(outDir))
		throw InputError(opts.output,
						 "cannot create the output folder" + (ec ? " (" + ec.message() + ")" : std::string()));
	if (opts.externalImages)
	{
		// The folder name MRPT's CRawlog::detectImagesDirectory looks for first.
		const fs::path imgDir = outDir / (out.stem().string() + "_Images");
		fs::create_directories(imgDir, ec);
		if (ec) throw InputError(imgDir.string(), "cannot create images folder (" + ec.message() + ")");
		sum.imagesDir = imgDir.string();
	}

	const std::size_t total = opts.maxFrames > 0 ? std::min(opts.maxFrames, src.frames().size()) : src.frames().size();
	CRawlogWriter writer(opts.output);
	std::uintmax_t imageBytes = 0;
	while (sum.frames < total)
	{
		if (cancel && cancel())
		{
			sum.interrupted = true;
			break;
		}
		auto obs = src.next();
		if (!obs) break;
		if (opts.externalImages)
		{
			// Copy the original PNG bytes: exact, and much faster than re-encoding.
			const TTumFrame& fr = src.frames()[src.lastIndex()];
			const std::string name = fs::path(fr.rgbPath).filename().string();
			const fs::path dst = fs::path(sum.imagesDir) / name;
			fs::copy_file(fr.rgbPath, dst, fs::copy_options::overwrite_existing, ec);
			if (ec) throw InputError(dst.string(), "cannot write image (" + ec.message() + ")");
			imageBytes += fs::file_size(dst, ec);
			mrpt::img::CImage ext;
			ext.setExternalStorage(name);
			obs->intensityImage = ext;
		}
		writer.write(*obs);
		const double t = observationTime(*obs);
		if (sum.frames == 0) sum.tFirst = t;
		sum.tLast = t;
		sum.frames++;
		if (progress) progress(sum.frames, total);
	}
	sum.bytes = writer.commit() + imageBytes;
	// The camera goes with the recording: a replay of the rawlog keeps the readout (issue 62 item 5).
	sum.cameraFile = recordingCameraPath(opts.output);
	writeFileAtomically(sum.cameraFile, formatCameraFile(src.camera(), "the camera of " + out.filename().string() +
																		   " (tum2rawlog, from " + opts.folder + ")"));

	const fs::path gt = fs::path(opts.folder) / "groundtruth.txt";
	if (fs::is_regular_file(gt, ec))
	{
		// Validate while copying, so a broken ground truth is reported now and not at evaluation.
		const auto traj = readTumTrajectory(gt.string());
		(void)traj;
		const fs::path dst = outDir / (out.stem().string() + "_groundtruth.txt");
		writeFileAtomically(dst.string(),
							[&](const std::string& tmp)
							{
								fs::copy_file(gt, tmp, fs::copy_options::overwrite_existing, ec);
								if (ec) throw InputError(dst.string(), "cannot write (" + ec.message() + ")");
							});
		sum.groundTruth = dst.string();
	}
	return sum;
}
}  // namespace mrpt_yesslam
