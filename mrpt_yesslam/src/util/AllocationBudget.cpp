// Process-wide allocation guards for reading untrusted rawlogs (see AllocationBudget.h).
#include "mrpt_yesslam/util/AllocationBudget.h"

#include <mrpt/core/aligned_allocator.h>

#include <cstdlib>
#include <exception>
#include <new>

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
// Bytes the current thread may still allocate (while MRPT deserialises one rawlog entry); null when
// no budget is in force (no limit). Set by CAllocationBudget.
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
void* operator new[](std::size_t n)
{
	return ::operator new(n);
}
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
void* operator new[](std::size_t n, const std::nothrow_t& t) noexcept
{
	return ::operator new(n, t);
}
void operator delete(void* p) noexcept
{
	std::free(p);
}
void operator delete(void* p, std::size_t) noexcept
{
	std::free(p);
}
void operator delete[](void* p) noexcept
{
	std::free(p);
}
void operator delete[](void* p, std::size_t) noexcept
{
	std::free(p);
}
void operator delete(void* p, const std::nothrow_t&) noexcept
{
	std::free(p);
}
void operator delete[](void* p, const std::nothrow_t&) noexcept
{
	std::free(p);
}
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

namespace mrpt_yesslam
{
CAllocationBudget::CAllocationBudget(std::size_t bytes) : left_(bytes)
{
	g_allocationBudget = &left_;
}

CAllocationBudget::~CAllocationBudget()
{
	release();
}

void CAllocationBudget::release()
{
	if (g_allocationBudget == &left_) g_allocationBudget = nullptr;
}
}  // namespace mrpt_yesslam
