// The longer variants of tests/test_ffr_spatial_validation.cpp (label slow): the same
// source with FLEXMBD_SPATIAL_VALIDATION_SLOW, which compiles only its slow tests.
#define FLEXMBD_SPATIAL_VALIDATION_SLOW 1
#include "test_ffr_spatial_validation.cpp"
