// Many machines: one render split over the processes of an MPI job (docs/distributed.md).
// `mpirun -np N ember render ...` (or Slurm's `srun`) starts N processes; each renders its share
// of every pixel's sample indices, and the film sums are added up on rank 0, which writes the
// image. Launched without mpirun, or built without MPI, ember is one process of a job of one.
#pragma once

#include "renderer/film.h"

#include <cstdint>

namespace ember {

class Cluster {
 public:
  // Joins the MPI job when the environment says this process was started by mpirun or srun
  // (OMPI_COMM_WORLD_SIZE, PMI_SIZE, PMIX_RANK); otherwise does nothing, so the same binary also
  // runs alone. Finalises MPI at exit.
  static Cluster& instance();

  int rank() const { return rank_; }
  int size() const { return size_; }
  bool isRoot() const { return rank_ == 0; }
  bool distributed() const { return size_ > 1; }

  // Rank r's share of `count` consecutive sample indices: [offset, offset + count) of them,
  // the remainder going one each to the first ranks.
  struct Share {
    uint64_t offset;
    int count;
  };
  Share shareOf(int count) const;

  // Adds every rank's film to rank 0's, rank by rank in order (so the result does not depend on
  // message timing); the other ranks' films are left as they were. Collective: every rank calls it.
  void reduceToRoot(Film& film) const;
  // True on every rank if `flag` is true on any (collective).
  bool any(bool flag) const;
  // The sum of `value` over all ranks, on every rank (collective).
  uint64_t sum(uint64_t value) const;

  Cluster(const Cluster&) = delete;
  Cluster& operator=(const Cluster&) = delete;

 private:
  Cluster();
  ~Cluster();
  int rank_ = 0;
  int size_ = 1;
  bool initialised_ = false;
};

// Whether this build of ember can join MPI jobs.
bool clusterSupport();

}  // namespace ember
