#include "media/vdb_loader.h"
