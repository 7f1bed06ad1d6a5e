// The admission bookkeeping alone: who may start, in which order, and what
// a waiting job is told.
#include "server/jobs/manager/admission.h"

#include <string>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

namespace mbopt::jobs::manager {
namespace {

using ::testing::HasSubstr;

TEST(Admission, WaitingJobsStartInOrderUnlessTheirOwnerIsAtTheLimit) {
  Admission admission(AdmissionLimits{/*max_running_jobs=*/3, /*max_running_jobs_per_user=*/1, 0});
  admission.Started("alice");
  admission.Enqueue(2, "job-a2", "alice");
  admission.Enqueue(3, "job-b1", "bob");
  admission.Enqueue(4, "job-b2", "bob");
  // alice is at her limit: bob's first job goes ahead of her waiting one.
  EXPECT_EQ(admission.NextToStart(), "job-b1");
  EXPECT_THAT(admission.WhyWaiting("job-a2"), HasSubstr("0 jobs ahead in the queue; user 'alice' runs 1 jobs"));
  admission.Remove("job-b1");
  admission.Started("bob");
  EXPECT_EQ(admission.NextToStart(), std::nullopt);  // both at their limits
  admission.Stopped("alice");
  EXPECT_EQ(admission.NextToStart(), "job-a2");
  admission.Remove("job-a2");
  admission.Started("alice");
  // Two run, under the server's 3, but bob is at his own limit: his job waits.
  EXPECT_EQ(admission.running(), 2);
  EXPECT_EQ(admission.NextToStart(), std::nullopt);
  EXPECT_THAT(admission.WhyWaiting("job-b2"), HasSubstr("--max-running-jobs-per-user 1"));
  EXPECT_EQ(admission.WhyWaiting("job-unknown"), "");
}

TEST(Admission, TheServerLimitHoldsEveryone) {
  Admission admission(AdmissionLimits{/*max_running_jobs=*/1, 0, /*max_queued_jobs_per_user=*/2});
  EXPECT_TRUE(admission.HasRoomFor("alice"));
  admission.Started("alice");
  EXPECT_FALSE(admission.HasRoomFor("bob"));
  admission.Enqueue(5, "job-5", "bob");
  admission.Enqueue(6, "job-6", "bob");
  EXPECT_EQ(admission.NextToStart(), std::nullopt);
  EXPECT_THAT(admission.WhyWaiting("job-6"),
              HasSubstr("1 job ahead in the queue; the server runs 1 jobs, its limit (--max-running-jobs 1)"));
  EXPECT_TRUE(admission.CheckQueueRoom("alice").ok());
  const absl::Status full = admission.CheckQueueRoom("bob");
  EXPECT_EQ(full.code(), absl::StatusCode::kResourceExhausted);
  EXPECT_THAT(full.message(), HasSubstr("user 'bob' already has 2 jobs waiting"));
  // Stopping a job nobody counted changes nothing.
  admission.Stopped("carol");
  EXPECT_EQ(admission.running(), 1);
  admission.Stopped("alice");
  EXPECT_EQ(admission.NextToStart(), "job-5");
}

TEST(Admission, NoLimitsMeansEveryJobStarts) {
  Admission admission(AdmissionLimits{});
  for (int i = 0; i < 100; ++i) admission.Started("alice");
  EXPECT_TRUE(admission.HasRoomFor("alice"));
  EXPECT_TRUE(admission.CheckQueueRoom("alice").ok());
}

}  // namespace
}  // namespace mbopt::jobs::manager

namespace mbopt::jobs::manager {
namespace {

// A waiting job's place and an owner's count of waiting jobs follow every
// change of the queue (both are kept, not recounted per question).
TEST(Admission, PlacesAndQueuedCountsFollowEveryChange) {
  Admission admission(AdmissionLimits{/*max_running_jobs=*/1, 0, /*max_queued_jobs_per_user=*/3});
  admission.Started("alice");
  for (int seq = 1; seq <= 6; ++seq) {
    admission.Enqueue(seq, "job-" + std::to_string(seq), seq % 2 == 0 ? "bob" : "carol");
  }
  EXPECT_THAT(admission.WhyWaiting("job-6"), HasSubstr("5 jobs ahead"));
  EXPECT_EQ(admission.CheckQueueRoom("bob").code(), absl::StatusCode::kResourceExhausted);
  admission.Remove("job-2");
  admission.Remove("job-3");
  EXPECT_THAT(admission.WhyWaiting("job-4"), HasSubstr("1 job ahead"));
  EXPECT_THAT(admission.WhyWaiting("job-6"), HasSubstr("3 jobs ahead"));
  EXPECT_TRUE(admission.CheckQueueRoom("bob").ok()) << "bob waits with 2 jobs now";
  // Queued again (a resume while the limits are reached) keeps its place by seq.
  admission.Enqueue(2, "job-2", "bob");
  EXPECT_THAT(admission.WhyWaiting("job-6"), HasSubstr("4 jobs ahead"));
  EXPECT_EQ(admission.CheckQueueRoom("bob").code(), absl::StatusCode::kResourceExhausted);
  admission.Enqueue(7, "job-2", "bob");  // the same job again: moved, not counted twice
  EXPECT_THAT(admission.WhyWaiting("job-2"), HasSubstr("4 jobs ahead"));
  EXPECT_EQ(admission.CheckQueueRoom("bob").code(), absl::StatusCode::kResourceExhausted);
  EXPECT_EQ(admission.queued(), 5);
  admission.Remove("job-2");
  admission.Remove("job-unknown");
  EXPECT_TRUE(admission.CheckQueueRoom("bob").ok());
  EXPECT_EQ(admission.queued(), 4);
}

}  // namespace
}  // namespace mbopt::jobs::manager
