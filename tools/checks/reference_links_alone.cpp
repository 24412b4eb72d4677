// Links the CPU reference (plume_reference) with nothing but what it declares it needs: were the
// reference to call into the bake or gpu/, this program would fail to link and the build with it.
// Run as a test, it only checks that the entry point is there.
#include "reference/reference.h"

int main() {
  auto* volatile entry = &plume::ref::renderReference;  // volatile: the object file is linked in
  return entry ? 0 : 1;
}
