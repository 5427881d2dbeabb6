"""Writers that hand wetcontact results to DEM codes: json, python, c, yade, csv."""
