#pragma once
// A readers-writer lock that lets a waiting writer in before new readers: the map-update lock's
// writers (a loop correction, a global BA's write-back) would otherwise wait, behind glibc's
// reader-preferring std::shared_mutex, for a moment when neither tracking nor local mapping holds
// it, which two overlapping readers may never leave. A writer takes the turnstile first, so readers
// that come after it wait there; the readers already in finish, then the writer runs.
#include <mutex>
#include <shared_mutex>

namespace mrpt_yesslam
{
/** std::shared_mutex with writer preference; usable with std::unique_lock and std::shared_lock. A
 * thread must not take it shared while it holds it: a writer waiting in between would deadlock
 * it (as with any writer-preferring lock). */
class CWriterFirstMutex
{
   public:
	/** Exclusive: waits for the readers inside, holding back the ones that come after. */
	void lock()
	{
		turnstile_.lock();
		rw_.lock();
	}
	void unlock()
	{
		rw_.unlock();
		turnstile_.unlock();
	}
	/** Shared: passes the turnstile (waits while a writer waits or runs), then joins the readers. */
	void lock_shared()
	{
		std::lock_guard<std::mutex> pass(turnstile_);
		rw_.lock_shared();
	}
	void unlock_shared() { rw_.unlock_shared(); }

   private:
	std::mutex turnstile_;
	std::shared_mutex rw_;
};
}  // namespace mrpt_yesslam
