// PLACEHOLDER: replaced by the zhang-kanai generator's spec reader (issue in progress).
#include "spec_models.h"

plume_status plume_zk_spec_generate(const char *file, const json_t *root, const plume_spec_options *options,
                                    plume_feather **out, plume_error *err)
{
	(void)root;
	(void)options;
	*out = NULL;
	return plume_error_set(err, PLUME_ERROR_UNSUPPORTED, "%s: the zhang-kanai model is not built yet", file);
}
