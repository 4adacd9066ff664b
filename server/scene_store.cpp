#include "server/scene_store.hpp"

namespace beamcast {

std::vector<std::string> SceneStore::put(const std::string& id,
                                         std::shared_ptr<const StoredScene> scene) {
  std::lock_guard lock(mu_);
  for (auto it = lru_.begin(); it != lru_.end(); ++it) {
    if (it->first == id) {
      bytes_ -= it->second->bytes;
      lru_.erase(it);
      break;
    }
  }
  bytes_ += scene->bytes;
  lru_.emplace_front(id, std::move(scene));
  std::vector<std::string> evicted;
  // The scene just stored stays even if it alone is over the byte limit (the
  // message size limit bounds it).
  while (lru_.size() > 1 && (static_cast<int>(lru_.size()) > max_scenes_ || bytes_ > max_bytes_)) {
    bytes_ -= lru_.back().second->bytes;
    evicted.push_back(lru_.back().first);
    lru_.pop_back();
  }
  return evicted;
}

std::shared_ptr<const StoredScene> SceneStore::get(const std::string& id) {
  std::lock_guard lock(mu_);
  for (auto it = lru_.begin(); it != lru_.end(); ++it) {
    if (it->first == id) {
      lru_.splice(lru_.begin(), lru_, it);
      return lru_.front().second;
    }
  }
  return nullptr;
}

std::vector<std::string> SceneStore::ids() const {
  std::lock_guard lock(mu_);
  std::vector<std::string> out;
  for (const auto& [id, scene] : lru_) out.push_back(id);
  return out;
}

bool SceneStore::erase(const std::string& id) {
  std::lock_guard lock(mu_);
  for (auto it = lru_.begin(); it != lru_.end(); ++it) {
    if (it->first == id) {
      bytes_ -= it->second->bytes;
      lru_.erase(it);
      return true;
    }
  }
  return false;
}

std::size_t SceneStore::count() const {
  std::lock_guard lock(mu_);
  return lru_.size();
}

std::uint64_t SceneStore::bytes() const {
  std::lock_guard lock(mu_);
  return bytes_;
}

}  // namespace beamcast
