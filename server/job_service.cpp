// Placeholder translation unit; the implementation lands with issue 4.
#include "server/job_service.h"
