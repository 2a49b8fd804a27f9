#include "downstream_perception/core/tsdf/tsdf_block_pool.h"

#include <cstdlib>
#include <new>

#include "downstream_perception/core/tsdf/tsdf_map.h"

#if defined(__linux__)
#include <sys/mman.h>
#endif

namespace downstream_perception {

TsdfBlockPool::~TsdfBlockPool() {
  // Blocks still handed out must not outlive the pool (TsdfMap declares its pool first).
  for (void* chunk : chunks_) std::free(chunk);
}

std::size_t TsdfBlockPool::blocksPerChunk() {
  return kChunkBytes / sizeof(TsdfBlock);
}

TsdfBlockPool::Ptr TsdfBlockPool::acquire() {
  void* slot = nullptr;
  if (!free_.empty()) {
    slot = free_.back();
    free_.pop_back();
  } else {
    if (chunks_.empty() || next_in_chunk_ == blocksPerChunk()) {
      void* chunk = std::aligned_alloc(kChunkBytes, kChunkBytes);
      if (chunk == nullptr) throw std::bad_alloc();
#if defined(__linux__) && defined(MADV_HUGEPAGE)
      madvise(chunk, kChunkBytes, MADV_HUGEPAGE);  // a hint: without huge pages nothing changes
#endif
      chunks_.push_back(chunk);
      next_in_chunk_ = 0;
    }
    slot = static_cast<unsigned char*>(chunks_.back()) + next_in_chunk_ * sizeof(TsdfBlock);
    ++next_in_chunk_;
  }
  ++in_use_;
  return Ptr(new (slot) TsdfBlock(), Deleter{this});
}

void TsdfBlockPool::trim() {
  if (in_use_ != 0) return;
  for (void* chunk : chunks_) std::free(chunk);
  chunks_.clear();
  free_.clear();
  next_in_chunk_ = 0;
}

void TsdfBlockPool::release(TsdfBlock* block) {
  block->~TsdfBlock();
  free_.push_back(block);
  --in_use_;
}

void TsdfBlockPool::Deleter::operator()(TsdfBlock* block) const {
  if (block != nullptr) pool->release(block);
}

}  // namespace downstream_perception
