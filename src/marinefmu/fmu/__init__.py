"""Making FMUs: the slave plumbing shared by the scripts in ``models/`` (:mod:`.slave`), every
FMU's variable table and the mapping to the models' parameters (:mod:`.tables`), the build and
validation (:mod:`.build`), units in modelDescription.xml (:mod:`.units`), the OSP model
descriptions (:mod:`.osp`), and the interface tables of the documentation read back from a built
FMU's modelDescription.xml (:mod:`.interface_table`)."""
