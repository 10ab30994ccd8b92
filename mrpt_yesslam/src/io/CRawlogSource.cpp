#include "mrpt_yesslam/io/CRawlogSource.h"

#include <mrpt/img/CImage.h>
#include <mrpt/obs/CActionCollection.h>
#include <mrpt/obs/CRawlog.h>
#include <mrpt/obs/CSensoryFrame.h>
#include <mrpt/serialization/CArchive.h>

#include <cstdlib>
#include <exception>
#include <cstring>
#include <cstdio>
#include <stdexcept>
#include <string>

#include <dlfcn.h>
#include <jpeglib.h>
#include <filesystem>

#include "mrpt_yesslam/io/RgbdObservation.h"
#include "mrpt_yesslam/util/AllocationBudget.h"
#include "mrpt_yesslam/util/Error.h"

namespace fs = std::filesystem;

// Guards against corrupt sizes in rawlog entries: util/AllocationBudget.cpp (replaces the global
// operator new and MRPT's aligned_malloc for the whole executable; limits apply only inside
// readObject()).

// Third guard (fuzz_rawlog, 2026-11-22; reproducer tests/fuzz/corpus/rawlog/crash-7ecb39ac...): a
// rawlog whose colour image is stored as a corrupt JPEG reaches libjpeg through MRPT's
// CImage::loadFromStreamAsJPEG, which keeps libjpeg's default error handler: it prints "Not a
// JPEG file" and calls exit(1), so the tool died without naming the file and without saving.
// We interpose jpeg_std_error (MRPT's libmrpt-img calls it through the PLT) and make the handler
// throw instead (after freeing the decoder's memory), which CRawlogSource reports as a corrupt
// entry. Callers that install their own handler afterwards (OpenCV's imread does) are unaffected.
// On x86-64 libjpeg has unwind tables, so the exception crosses its frames.
extern "C" struct jpeg_error_mgr* jpeg_std_error(struct jpeg_error_mgr* err)
{
	using Fn = struct jpeg_error_mgr* (*)(struct jpeg_error_mgr*);
	static const Fn real = reinterpret_cast<Fn>(dlsym(RTLD_NEXT, "jpeg_std_error"));
	if (!real) throw std::runtime_error("libjpeg's jpeg_std_error not found");
	struct jpeg_error_mgr* e = real(err);
	e->error_exit = [](j_common_ptr cinfo)
	{
		char msg[JMSG_LENGTH_MAX] = "";
		(*cinfo->err->format_message)(cinfo, msg);
		// MRPT will not get to free the decoder: free its memory pools here. Looked up like the real
		// jpeg_std_error, so that we need no link dependency on libjpeg of our own.
		using Destroy = void (*)(j_common_ptr);
		static const Destroy destroy = reinterpret_cast<Destroy>(dlsym(RTLD_DEFAULT, "jpeg_destroy"));
		if (destroy) destroy(cinfo);
		throw std::runtime_error(std::string("corrupt JPEG image: ") + msg);
	};
	return e;
}

namespace mrpt_yesslam
{
CRawlogSource::CRawlogSource(const std::string& path, const TOptions& opts) : path_(path), opts_(opts)
{
	std::error_code ec;
	if (!fs::exists(path, ec)) throw InputError(path, "file not found");
	if (fs::is_directory(path, ec)) throw InputError(path, "is a folder, expected a .rawlog file");
	file_ = std::make_unique<mrpt::io::CFileGZInputStream>();
	if (fs::file_size(path, ec) == 0) throw InputError(path, "rawlog is empty (0 bytes)");
	if (!file_->open(path)) throw InputError(path, "cannot open rawlog");
	// External images ("<name>_Images/") are resolved against one global MRPT path. We look for the
	// folders MRPT's convention names ourselves: CRawlog::detectImagesDirectory in MRPT 2.5 joins
	// the folder and file name without a separator and so misses "<dir>/<name>_Images".
	const fs::path p(path);
	const fs::path dir = p.parent_path().empty() ? fs::path(".") : p.parent_path();
	for (const std::string& cand :
		 {p.stem().string() + "_Images", p.stem().string() + "_images", std::string("Images")})
		if (fs::is_directory(dir / cand, ec))
		{
			imagesDir_ = (dir / cand).string();
			break;
		}
	if (imagesDir_.empty()) imagesDir_ = mrpt::obs::CRawlog::detectImagesDirectory(path);
	// None there: the conventional name, so that an error names the folder a user should create.
	if (!fs::is_directory(imagesDir_, ec)) imagesDir_ = (dir / (p.stem().string() + "_Images")).string();
	mrpt::img::CImage::setImagesPathBase(imagesDir_);
}

mrpt::serialization::CSerializable::Ptr CRawlogSource::readObject()
{
	// gzeof() only turns true after a failed read, so the end is recognised afterwards: an
	// exception with no byte consumed is the clean end of the file; anything else is damage.
	const uint64_t before = file_->getPosition();
	// One entry (an RGB-D frame: images, depth, maybe a point cloud: a few MB, ~100 MB at 4K with
	// clouds) never needs 256 MiB.
	CAllocationBudget budget(std::size_t(1) << 28);
	try
	{
		auto arch = mrpt::serialization::archiveFrom(*file_);
		auto o = arch.ReadObject();
		entries_++;
		return o;
	}
	catch (const std::exception& e)
	{
		budget.release();  // the message below must not fail for lack of budget
		if (file_->getPosition() == before) return nullptr;
		throw InputError(path_, "corrupt or truncated rawlog at entry " + std::to_string(entries_ + 1) + " (" +
									exceptionSummary(e.what()) + ")");
	}
}

namespace
{
// MRPT deserialises these flags by reading a raw byte into a bool; a corrupt file can leave any
// value in it, and reading such a bool is undefined behaviour (fuzz_rawlog, UBSan: "load of value
// 19, which is not a valid value for type 'bool'"; reproducer crash-b44054a7...). Normalised from
// the byte before anything reads them.
void normaliseBool(bool& b)
{
	unsigned char raw = 0;
	std::memcpy(&raw, &b, 1);
	b = raw != 0;
}
}  // namespace

void CRawlogSource::enqueue(const mrpt::serialization::CSerializable::Ptr& o)
{
	if (!o) return;
	if (auto scan = std::dynamic_pointer_cast<mrpt::obs::CObservation3DRangeScan>(o))
	{
		for (bool* b : {&scan->hasPoints3D, &scan->hasRangeImage, &scan->range_is_depth, &scan->hasIntensityImage,
						&scan->hasConfidenceImage})
			normaliseBool(*b);
		if (opts_.sensorLabel.empty() || scan->sensorLabel == opts_.sensorLabel)
			pending_.push_back(scan);
		else
			skipped_++;
		return;
	}
	if (auto sf = std::dynamic_pointer_cast<mrpt::obs::CSensoryFrame>(o))
	{
		for (const auto& obs : *sf) enqueue(obs);
		return;
	}
	// Actions (odometry) and other sensors carry no RGB-D frame.
	if (!std::dynamic_pointer_cast<mrpt::obs::CActionCollection>(o)) skipped_++;
}

mrpt::obs::CObservation3DRangeScan::Ptr CRawlogSource::next()
{
	while (pending_.empty())
	{
		auto o = readObject();
		if (!o)
		{
			if (frames_ == 0)
			{
				if (entries_ == 0) throw InputError(path_, "not a rawlog, or a rawlog with no entries");
				throw InputError(
					path_,
					"no RGB-D frames (CObservation3DRangeScan with colour and depth" +
						(opts_.sensorLabel.empty() ? std::string() : " and sensor label '" + opts_.sensorLabel + "'") +
						") among its " + std::to_string(entries_) + " entries");
			}
			return nullptr;
		}
		enqueue(o);
	}
	auto obs = pending_.front();
	pending_.pop_front();
	frames_++;
	const std::string where = path_ + ": frame " + std::to_string(frames_);
	try
	{
		obs->load();  // external 3D data, if any
		if (obs->hasIntensityImage && obs->intensityImage.isExternallyStored()) obs->intensityImage.forceLoad();
	}
	catch (const std::exception& e)
	{
		// The folder in full: MRPT resolves it against the working directory, which is rarely where
		// the user thinks it looked.
		std::error_code ec;
		const std::string dir =
			fs::absolute(imagesDir_.empty() ? fs::path(".") : fs::path(imagesDir_), ec).lexically_normal().string();
		if (!fs::is_directory(dir, ec))
			throw InputError(where, "cannot load external data: the images folder '" + dir + "' does not exist");
		throw InputError(where, "cannot load external data (looked in '" + dir + "'): " + exceptionSummary(e.what()));
	}
	validateRgbdObservation(*obs, where);
	return obs;
}
}  // namespace mrpt_yesslam
