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
#include <new>

#include <mrpt/core/aligned_allocator.h>

#include "mrpt_yesslam/io/RgbdObservation.h"
#include "mrpt_yesslam/util/Error.h"

namespace fs = std::filesystem;

// Guard for corrupt rawlogs (found by fuzz_rawlog; reproducer in tests/fuzz/corpus/rawlog and
// tests/data/bad/rawlog_huge_image.rawlog). MRPT 2.5 deserialises a range image by allocating
// whatever size the file states through mrpt::aligned_malloc, which returns nullptr when that
// fails; the vector then writes through the null pointer and the process dies with SIGSEGV inside
// MRPT. Defining the function here interposes it (libmrpt-obs calls it through the PLT) with one
// that behaves like operator new: it throws std::bad_alloc, which CRawlogSource turns into
// "corrupt or truncated rawlog". Memory still comes from ::aligned_alloc, so MRPT's
// aligned_free (::free) releases it as before. Single blocks above 512 MiB are refused too: a
// corrupt size that the machine could satisfy would otherwise eat gigabytes (zero-filled) before
// the read fails (fuzz_rawlog's out-of-memory reproducer); no image or cloud we read comes near it.
namespace
{
// Bytes the current thread may still allocate while MRPT deserialises one rawlog entry; null when
// no entry is being read (no limit). See readObject().
thread_local std::size_t* g_allocationBudget = nullptr;

void chargeAllocation(std::size_t n)
{
	// Never while unwinding: MRPT's destructors allocate (a half-read range scan resizes its
	// images when destroyed), and a throw from a destructor terminates the program (fuzz_rawlog,
	// crash-58254d49...).
	if (!g_allocationBudget || std::uncaught_exceptions() > 0) return;
	if (n > *g_allocationBudget) throw std::bad_alloc();
	*g_allocationBudget -= n;
}
}  // namespace

// The second guard (fuzz_rawlog's "timeout" findings, now in tests/fuzz/corpus/rawlog): a corrupt
// count in a CActionCollection makes MRPT resize a std::deque to billions of elements, allocated
// in 512-byte nodes through plain operator new, so no single block is large: it took 1-4 minutes
// and ~14 GB before failing. Our executables replace the global operator new (ASan and UBSan
// builds included: memory still comes from malloc and goes back to free) so that, while one
// rawlog entry is being read, allocations are charged to a budget; over it, std::bad_alloc, and
// CRawlogSource reports the corrupt entry at once. Outside readObject() nothing changes.
#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC diagnostic push
// Our delete frees what our new mallocs; GCC cannot see that pairing across the definitions.
#pragma GCC diagnostic ignored "-Wmismatched-new-delete"
#endif
void* operator new(std::size_t n)
{
	chargeAllocation(n);
	if (n == 0) n = 1;
	for (;;)
	{
		if (void* p = std::malloc(n)) return p;
		const std::new_handler h = std::get_new_handler();
		if (!h) throw std::bad_alloc();
		h();
	}
}
// Every other non-aligned form goes through the same malloc/free pair, so that no pointer is ever
// released by a different allocator than the one that made it (ASan checks exactly that; libstdc++
// frees std::stable_sort's nothrow buffers with plain delete, for instance). The aligned forms are
// left to the runtime: they pair among themselves.
void* operator new[](std::size_t n) { return ::operator new(n); }
void* operator new(std::size_t n, const std::nothrow_t&) noexcept
{
	try
	{
		return ::operator new(n);
	}
	catch (...)
	{
		return nullptr;
	}
}
void* operator new[](std::size_t n, const std::nothrow_t& t) noexcept { return ::operator new(n, t); }
void operator delete(void* p) noexcept { std::free(p); }
void operator delete(void* p, std::size_t) noexcept { std::free(p); }
void operator delete[](void* p) noexcept { std::free(p); }
void operator delete[](void* p, std::size_t) noexcept { std::free(p); }
void operator delete(void* p, const std::nothrow_t&) noexcept { std::free(p); }
void operator delete[](void* p, const std::nothrow_t&) noexcept { std::free(p); }
#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC diagnostic pop
#endif

void* mrpt::aligned_malloc(size_t size, size_t alignment)
{
	constexpr size_t kMaxBlock = size_t(1) << 29;
	if (size > kMaxBlock) throw std::bad_alloc();
	chargeAllocation(size);
	if (alignment < sizeof(void*)) alignment = sizeof(void*);
	if (size % alignment != 0) size = (size / alignment + 1) * alignment;
	void* p = ::aligned_alloc(alignment, size == 0 ? alignment : size);
	if (!p) throw std::bad_alloc();
	return p;
}

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
	for (const std::string& cand : {p.stem().string() + "_Images", p.stem().string() + "_images", std::string("Images")})
		if (fs::is_directory(dir / cand, ec))
		{
			imagesDir_ = (dir / cand).string();
			break;
		}
	if (imagesDir_.empty()) imagesDir_ = mrpt::obs::CRawlog::detectImagesDirectory(path);
	mrpt::img::CImage::setImagesPathBase(imagesDir_);
}

mrpt::serialization::CSerializable::Ptr CRawlogSource::readObject()
{
	// gzeof() only turns true after a failed read, so the end is recognised afterwards: an
	// exception with no byte consumed is the clean end of the file; anything else is damage.
	const uint64_t before = file_->getPosition();
	// One entry (an RGB-D frame: images, depth, maybe a point cloud: a few MB, ~100 MB at 4K with
	// clouds) never needs 256 MiB.
	std::size_t budget = std::size_t(1) << 28;
	struct TBudgetScope
	{
		explicit TBudgetScope(std::size_t* b) { g_allocationBudget = b; }
		~TBudgetScope() { g_allocationBudget = nullptr; }
	} scope(&budget);
	try
	{
		auto arch = mrpt::serialization::archiveFrom(*file_);
		auto o = arch.ReadObject();
		entries_++;
		return o;
	}
	catch (const std::exception& e)
	{
		g_allocationBudget = nullptr;  // the message below must not fail for lack of budget
		if (file_->getPosition() == before) return nullptr;
		throw InputError(
			path_, "corrupt or truncated rawlog at entry " + std::to_string(entries_ + 1) + " (" + exceptionSummary(e.what()) + ")");
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
					path_, "no RGB-D frames (CObservation3DRangeScan with colour and depth" +
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
		throw InputError(where, "cannot load external data (looked in '" + imagesDir_ + "'): " + exceptionSummary(e.what()));
	}
	validateRgbdObservation(*obs, where);
	return obs;
}
}  // namespace mrpt_yesslam
