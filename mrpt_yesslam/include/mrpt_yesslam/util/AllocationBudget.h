#pragma once
// Limits what one thread may allocate while it deserialises untrusted data. MRPT 2.5 allocates
// whatever sizes a corrupt rawlog states (a range image of 2^40 bytes, a deque of billions of
// elements) and then crashes or eats the machine's memory; with a budget in force, allocations
// beyond it throw std::bad_alloc, which the reader reports as a corrupt entry.
//
// To see every allocation, AllocationBudget.cpp replaces the global operator new/delete (all
// non-aligned forms, through malloc/free, so ASan builds pair them correctly) and interposes MRPT's
// mrpt::aligned_malloc, for the whole executable. Outside a budget's lifetime nothing changes,
// except that single aligned blocks above 512 MiB are always refused (nothing we read needs one).
#include <cstddef>

namespace mrpt_yesslam
{
/** While it lives, the current thread may allocate at most `bytes` (RAII; not nestable). */
class CAllocationBudget
{
   public:
	explicit CAllocationBudget(std::size_t bytes);
	~CAllocationBudget();
	CAllocationBudget(const CAllocationBudget&) = delete;
	CAllocationBudget& operator=(const CAllocationBudget&) = delete;
	/** Lifts the limit before the end of the scope (e.g. to build an error message). */
	void release();

   private:
	std::size_t left_;
};
}  // namespace mrpt_yesslam
