// The map's lock in the server (mvog_ros/writer_preferring_mutex.h): readers share it, a writer
// excludes everyone, and a waiting writer goes before new readers, so that queries arriving
// without a pause cannot keep insertion out.
#include <gtest/gtest.h>

#include <atomic>
#include <mutex>
#include <shared_mutex>
#include <thread>

#include "mvog_ros/writer_preferring_mutex.h"

namespace {

using mvog_ros::WriterPreferringMutex;

TEST(WriterPreferringMutex, ReadersShareAndAWriterExcludesEveryone) {
  WriterPreferringMutex mutex;
  ASSERT_TRUE(mutex.try_lock_shared());
  ASSERT_TRUE(mutex.try_lock_shared());
  EXPECT_FALSE(mutex.try_lock());
  mutex.unlock_shared();
  mutex.unlock_shared();
  ASSERT_TRUE(mutex.try_lock());
  EXPECT_FALSE(mutex.try_lock_shared());
  mutex.unlock();
  std::shared_lock<WriterPreferringMutex> reading(mutex);
  EXPECT_TRUE(reading.owns_lock());
}

TEST(WriterPreferringMutex, AWaitingWriterGoesBeforeNewReaders) {
  WriterPreferringMutex mutex;
  std::atomic<bool> written{false};
  std::shared_lock<WriterPreferringMutex> first_reader(mutex);
  std::thread writer([&] {
    std::unique_lock<WriterPreferringMutex> lock(mutex);
    written = true;
  });
  // New readers get in until the writer waits; from then on, none does (a reader-preferring
  // lock, like std::shared_mutex on glibc, would let every one in and starve the writer).
  constexpr long kMaxTries = 1000000;
  long tries = 0;
  while (tries < kMaxTries && mutex.try_lock_shared()) {
    mutex.unlock_shared();
    std::this_thread::yield();
    ++tries;
  }
  EXPECT_LT(tries, kMaxTries) << "new readers kept getting in ahead of a waiting writer";
  EXPECT_FALSE(written);
  first_reader.unlock();
  writer.join();
  EXPECT_TRUE(written);
}

}  // namespace
