"""Writers that hand wetcontact results to other tools and DEM codes: csv, yade, ..."""
