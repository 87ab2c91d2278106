// Worker threads kept for the life of the process, for the batched map update.
//
// Why: a thread started per call costs its start-up and, worse, a fresh copy of the
// update's per-thread buffers (about 270 kB, update.cpp's thread_buffers), so a 64-map
// step on two threads ran slower than on one. Kept workers keep their buffers: after the
// first call, a parallel call allocates nothing and only wakes them.
//
// Results never depend on the pool: the caller splits the work into blocks and each block
// runs the same code whichever thread takes it. Two guards keep it safe to use from
// Python:
// - fork: a child process has the parent's pool object but none of its threads, so the
//   pool remembers the process that made it, and a child makes its own (the parent's is
//   left alone: its mutexes may have been copied locked);
// - concurrent callers (two Python threads, each with the GIL released): one caller at a
//   time has the workers; another runs all of its blocks on its own thread instead of
//   waiting.
#pragma once

#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <condition_variable>
#include <cstdint>
#include <exception>
#include <functional>
#include <memory>
#include <mutex>
#include <thread>
#include <vector>

namespace bearing::core {

class WorkerPool {
public:
    // Runs block(0) .. block(blocks - 1), block 0 on the calling thread and the others on
    // workers (started on first need, then kept); returns when all are done and rethrows
    // the first block's exception, by block order.
    static void run(int64_t blocks, const std::function<void(int64_t)>& block) {
        if (blocks <= 1) {
            if (blocks == 1) block(0);
            return;
        }
        WorkerPool& pool = instance();
        std::unique_lock<std::mutex> turn(pool.turn_, std::try_to_lock);
        if (!turn.owns_lock()) {
            serial(blocks, block);  // another caller has the workers
            return;
        }
        pool.run_blocks(blocks, block);
    }

private:
    WorkerPool() : owner_(::getpid()) {}

    static WorkerPool& instance() {
        // Never destroyed: workers wait on it until the process ends. No lock here: one
        // copied locked by a fork would hang the child.
        static std::atomic<WorkerPool*> current{nullptr};
        WorkerPool* pool = current.load();
        while (pool == nullptr || pool->owner_ != ::getpid()) {
            auto* made = new WorkerPool();  // the first, or a forked child's own
            if (current.compare_exchange_strong(pool, made)) return *made;
            delete made;  // another caller made it first: `pool` now holds theirs
        }
        return *pool;
    }

    static void serial(int64_t blocks, const std::function<void(int64_t)>& block) {
        std::exception_ptr first;
        for (int64_t b = 0; b < blocks; ++b) {
            try {
                block(b);
            } catch (...) {
                if (!first) first = std::current_exception();
            }
        }
        if (first) std::rethrow_exception(first);
    }

    void run_blocks(int64_t blocks, const std::function<void(int64_t)>& block) {
        std::vector<std::exception_ptr> errors(static_cast<size_t>(blocks));
        const std::function<void(int64_t)> guarded = [&](int64_t b) {
            try {
                block(b);
            } catch (...) {
                errors[static_cast<size_t>(b)] = std::current_exception();
            }
        };
        int64_t on_workers = 0;
        {
            std::lock_guard<std::mutex> lock(mutex_);
            while (static_cast<int64_t>(workers_.size()) < blocks - 1) {
                try {
                    const int64_t index = static_cast<int64_t>(workers_.size());
                    workers_.emplace_back([this, index] { work(index); });
                } catch (...) {
                    break;  // no more threads to start: the caller runs the rest itself
                }
            }
            on_workers = std::min<int64_t>(blocks - 1, static_cast<int64_t>(workers_.size()));
            task_ = &guarded;
            active_ = on_workers;
            pending_ = on_workers;
            ++generation_;
        }
        wake_.notify_all();
        guarded(0);
        for (int64_t b = 1 + on_workers; b < blocks; ++b) guarded(b);
        {
            std::unique_lock<std::mutex> lock(mutex_);
            done_.wait(lock, [this] { return pending_ == 0; });
            task_ = nullptr;
        }
        for (const std::exception_ptr& error : errors) {
            if (error) std::rethrow_exception(error);
        }
    }

    // Worker `index` runs block index + 1 of each call that has one for it.
    void work(int64_t index) {
        uint64_t seen = 0;
        for (;;) {
            const std::function<void(int64_t)>* task = nullptr;
            {
                std::unique_lock<std::mutex> lock(mutex_);
                wake_.wait(lock, [&] { return generation_ != seen; });
                seen = generation_;
                if (index >= active_) continue;
                task = task_;
            }
            (*task)(index + 1);
            {
                std::lock_guard<std::mutex> lock(mutex_);
                if (--pending_ == 0) done_.notify_one();
            }
        }
    }

    const pid_t owner_;
    std::mutex turn_;   // one caller at a time has the workers
    std::mutex mutex_;  // guards everything below
    std::condition_variable wake_;
    std::condition_variable done_;
    std::vector<std::thread> workers_;
    const std::function<void(int64_t)>* task_ = nullptr;
    int64_t active_ = 0;   // workers with a block in this call
    int64_t pending_ = 0;  // of those, still running
    uint64_t generation_ = 0;
};

}  // namespace bearing::core
